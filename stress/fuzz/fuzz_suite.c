/* fuzz_suite.c — libFuzzer harness of the suite journal reader
 * (pd_suite_journal_open with resume, and the record lines' parsers
 * pd_suite_osc_parse and pd_suite_scene_parse, cli/suite_journal.c): the
 * input is written as a journal and resumed, each line read back as an
 * oscillator's and as a scene's summary (the scene: examples/scenes/
 * two-sdof.json, or $POUND_FUZZ_SCENE); then the whole input is parsed as
 * one line's body, past the checksum (a hostile file can forge it).
 *
 * So that the fuzzer gets past the header check, the key is the input's own
 * key line when it has one.  Every record accepted must be one of the
 * suite's (k in [0, NREC)); a scene's summary read back must fit the scene
 * (pd_scene_result_fits) and is freed (LeakSanitizer sees the rest). */
#include "fuzz_common.h"
#include "pd_journal.h"

#define NREC 16

typedef struct reader {
    const pd_scene *sc;
    pd_suite_names names;
} reader;

static int read_line(const char *body, size_t len, void *ctx)
{
    reader *r = ctx;
    pd_osc_summary o;
    pd_scene_summary s;
    int k = -1, ok = 0;
    if (!pd_suite_osc_parse(body, len, NREC, &k, &o, &r->names)) {
        if (k < 0 || k >= NREC)
            abort();
        ok = 1;
    }
    if (r->sc && !pd_suite_scene_parse(body, len, r->sc, NREC, &k, &s, &r->names)) {
        if (k < 0 || k >= NREC || !pd_scene_result_fits(r->sc, &s.r) ||
            !pd_scene_result_fits(r->sc, &s.free))
            abort();
        pd_scene_summary_free(&s);
        ok = 1;
    }
    return ok ? 0 : -1;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static pd_scene *sc;
    static int tried;
    char path[1100], key[4096] = "v=1";
    pd_err err;
    if (!tried) { /* the scene, once */
        const char *f = getenv("POUND_FUZZ_SCENE");
        tried = 1;
        if (pd_scene_load(f ? f : "examples/scenes/two-sdof.json", &sc, &err))
            sc = NULL;
    }
    fuzz_key(data, size, "pound-suite-journal 1\nkey ", key, sizeof key);
    fuzz_write("suite.journal", data, size, path, sizeof path);
    reader r = {.sc = sc};
    pd_journal j;
    memset(&err, 0, sizeof err);
    int rc = pd_suite_journal_open(&j, path, key, 1, read_line, &r, &err);
    if (rc != PD_OK && (!err.msg[0] || strchr(err.msg, '\n')))
        abort(); /* one non-empty line */
    pd_journal_close(&j, 0);
    /* the input as one line's body, past the checksum (which a writer of a
     * hostile file can forge) */
    read_line((const char *)data, size, &r);
    pd_suite_names_free(&r.names);
    return 0;
}
