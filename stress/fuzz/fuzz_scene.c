/* fuzz_scene.c — libFuzzer harness of the scene reader (pd_scene_load,
 * problems/scene_json.c): JSON text in, a scene or one error out.  An
 * error must come with a one-line message (no newline in it); a scene that
 * loads must also resolve its run options without trouble. */
#include "fuzz_common.h"
#include "pd_problems.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[1024];
    pd_scene *sc = NULL;
    pd_err err;
    memset(&err, 0, sizeof err);
    fuzz_write("in.json", data, size, path, sizeof path);
    int rc = pd_scene_load(path, &sc, &err);
    if (rc != PD_OK) {
        if (sc)
            abort(); /* an error hands nothing over */
        if (!err.msg[0] || strchr(err.msg, '\n'))
            abort(); /* the message is one non-empty line */
        return 0;
    }
    if (!sc)
        abort();
    pd_run_opts in = pd_run_default_opts(), out;
    (void)pd_scene_resolve_opts(sc, &in, &out, &err);
    pd_scene_free(sc);
    return 0;
}
