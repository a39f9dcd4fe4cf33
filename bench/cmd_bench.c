/* cmd_bench.c — `pound bench [--lcp] [--engine] [--scene] [--rtol] [--spectrum] [--records]
 * [--startup] [--json] [--shared DIR]`: the flags, then the drivers of
 * bench/ (pd_bench.h) after the machine's line. */
#include <errno.h>
#include <string.h>
#include <sys/stat.h>

#include "pd_bench.h"
#include "pd_cli.h"

int pd_cmd_bench(int argc, char **argv)
{
    int json = 0, want_lcp = 0, want_engine = 0, want_scene = 0, want_spectrum = 0;
    int want_records = 0, want_startup = 0, want_rtol = 0;
    const char *shared = "../shared";
    int shared_given = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--json"))
            json = 1;
        else if (!strcmp(argv[i], "--lcp"))
            want_lcp = 1;
        else if (!strcmp(argv[i], "--engine"))
            want_engine = 1;
        else if (!strcmp(argv[i], "--scene"))
            want_scene = 1;
        else if (!strcmp(argv[i], "--rtol"))
            want_rtol = 1;
        else if (!strcmp(argv[i], "--records"))
            want_records = 1;
        else if (!strcmp(argv[i], "--spectrum"))
            want_spectrum = 1;
        else if (!strcmp(argv[i], "--startup"))
            want_startup = 1;
        else if (!strcmp(argv[i], "--shared") && i + 1 < argc) {
            shared = argv[++i];
            shared_given = 1;
        } else if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            puts("usage: pound bench [--lcp] [--engine] [--scene] [--rtol] [--spectrum]\n"
                 "                   [--records] [--startup] [--json]\n"
                 "                   [--shared DIR]\n"
                 "  no selection runs every benchmark; --shared points at the shared data\n"
                 "  folder holding lcp/siconos (default ../shared, skipped when absent; a named\n"
                 "  folder must exist); the processor and the\n"
                 "  instruction set of the vector kernels come first, every time as the wall\n"
                 "  clock and the thread's CPU time\n"
                 "  --lcp: the LCP solvers on the Siconos set and chains of 10 ... 10^5 contacts\n"
                 "  --engine: Moreau-Jean steps/s on the one-wall oscillator (scalar, batched and\n"
                 "  general kernels) beside the bound of each step's dependency chain\n"
                 "  --scene: ns per DOF-step on rows (`--chain N`) of 10 ... 10^5 SDOFs, the "
                 "one-wall\n"
                 "  scene against the oscillator\n"
                 "  --rtol: Moreau-Jean to a tolerance: the one-wall cost against fixed steps at\n"
                 "  1e-5, error and CPU for rtol 1e-2 ... 1e-6 on one wall, rows of 2, 10, 100, a\n"
                 "  compressed cluster and a record, ns per DOF-step on a row of 10^4 SDOFs\n"
                 "  --spectrum: the paper-scale sweep, serial with each instruction set the\n"
                 "  processor has (POUND_ISA caps it) and on 2 OpenMP threads\n"
                 "  --records: every shared record x 200 Pi2 x 4 Pi3 x 3 eps, exact reference and\n"
                 "  Moreau-Jean, on 2 OpenMP threads\n"
                 "  --startup: the time a pound process takes to start, against /bin/true");
            return 0;
        } else
            return pd_cli_usage_error("bench: unknown flag '%s'", argv[i]);
    }
    /* a folder the user names must be there (the default's absence skips) */
    struct stat sh;
    if (shared_given && (stat(shared, &sh) != 0 || !S_ISDIR(sh.st_mode)))
        return pd_cli_usage_error("--shared %s: %s", shared,
                                  stat(shared, &sh) != 0 ? strerror(errno) : "not a folder");
    if (!want_lcp && !want_engine && !want_scene && !want_spectrum && !want_records &&
        !want_startup && !want_rtol)
        want_lcp = want_engine = want_scene = want_spectrum = want_records = want_startup =
            want_rtol = 1;

    pd_json js, *jp = NULL;
    if (json) {
        pd_json_init(&js, stdout);
        pd_json_begin_object(&js, NULL);
        jp = &js;
    }
    int rc = pd_bench_machine(jp);
    if (want_lcp)
        rc |= pd_bench_lcp(jp, shared);
    if (want_engine)
        rc |= pd_bench_engine(jp);
    if (want_scene)
        rc |= pd_bench_scene(jp);
    if (want_rtol)
        rc |= pd_bench_adapt(jp);
    if (want_spectrum)
        rc |= pd_bench_spectrum(jp);
    if (want_records)
        rc |= pd_bench_records(jp, shared);
    if (want_startup)
        rc |= pd_bench_startup(jp);
    if (json) {
        pd_json_end_object(&js);
        pd_json_finish(&js);
    }
    return rc ? 1 : 0;
}
