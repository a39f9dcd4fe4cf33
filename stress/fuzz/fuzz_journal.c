/* fuzz_journal.c — libFuzzer harness of the spectrum journal reader
 * (pd_spec_journal_open with resume, cli/spectrum_journal.c): the input is
 * written as OUT.partial and resumed.
 *
 * So that the fuzzer gets past the header check, the key the reader is
 * given is the input's own key line ("pound-spectrum-journal 1\nkey ...\n")
 * when it has one, and the number of tasks its "tasks=N" (at most 4096);
 * inputs of odd length are given that key with its last byte changed, to
 * exercise the "belongs to a different sweep" path.  Every record the reader
 * accepts must have a task in [0, ntasks). */
#include "fuzz_common.h"
#include "pd_spectrum.h"

#define MAXTASKS 4096

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char out[1024], path[1100], key[4096] = "v=1 tasks=16";
    long ntasks = 16;
    size_t len = fuzz_key(data, size, "pound-spectrum-journal 1\nkey ", key, sizeof key);
    if (len > 0) {
        const char *t = strstr(key, "tasks=");
        if (t) {
            long v = strtol(t + 6, NULL, 10);
            if (v >= 1 && v <= MAXTASKS)
                ntasks = v;
        }
        if (size % 2)
            key[len - 1] ^= 1;
    }
    snprintf(out, sizeof out, "%s/out.h5", fuzz_dir());
    fuzz_write("out.h5.partial", data, size, path, sizeof path);
    pd_spec_result *res = calloc((size_t)ntasks, sizeof *res);
    if (!res)
        abort();
    pd_spec_journal j;
    pd_err err;
    long loaded = 0;
    memset(&err, 0, sizeof err);
    int rc = pd_spec_journal_open(&j, out, key, ntasks, 1, res, &loaded, &err);
    if (rc != PD_OK) {
        if (!err.msg[0] || strchr(err.msg, '\n'))
            abort(); /* one non-empty line */
    } else {
        long done = 0;
        for (long t = 0; t < ntasks; t++)
            done += res[t].done != 0;
        if (loaded < 0 || loaded > ntasks || done != loaded)
            abort(); /* the count of resumed tasks is what was loaded */
    }
    pd_spec_journal_close(&j, 0);
    free(res);
    return 0;
}
