/* main.c — `pound`: dispatch to a subcommand; temporary output files
 * removed on SIGINT/SIGTERM; standard output checked at the end. */
#include <errno.h>
#include <string.h>

#include "pd_cli.h"
#include "pd_output.h"
#include "pd_spectrum.h"

static const char usage[] =
    "usage: pound <command> [options]\n"
    "\n"
    "commands:\n"
    "  simulate   one run of the pounding oscillator or a scene (Moreau-Jean, event-driven,\n"
    "             penalty), under a pulse or a record\n"
    "  compare    Moreau-Jean (and penalty) against the event-driven reference\n"
    "  converge   errors and cost as dt shrinks; work-precision charts\n"
    "  spectrum   response spectra Pi1(Pi2) over lists of Pi3, eps, xi, pulses (OpenMP, MPI)\n"
    "  record F   ground-motion measures and the fitted pulse of strong-motion records\n"
    "  lcp FILE   solve one linear complementarity problem (Lemke, structured, PGS)\n"
    "  bench      performance figures (--lcp, --engine, --scene, --spectrum)\n"
    "\n"
    "`pound <command> --help` lists a command's options; docs/ has the details.\n";

/* The subcommand argv[1] names: its exit status. */
static int dispatch(int argc, char **argv)
{
    if (argc < 2) /* bad input: one line */
        return pd_cli_usage_error("no command given: simulate, compare, converge, spectrum, lcp, "
                                  "record or bench (`pound --help` for usage)");
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        fputs(usage, stdout);
        return 0;
    }
    const char *cmd = argv[1];
    if (!strcmp(cmd, "lcp"))
        return pd_cmd_lcp(argc - 1, argv + 1);
    if (!strcmp(cmd, "simulate"))
        return pd_cmd_simulate(argc - 1, argv + 1);
    if (!strcmp(cmd, "compare"))
        return pd_cmd_compare(argc - 1, argv + 1);
    if (!strcmp(cmd, "converge"))
        return pd_cmd_converge(argc - 1, argv + 1);
    if (!strcmp(cmd, "spectrum"))
        return pd_cmd_spectrum(argc - 1, argv + 1);
    if (!strcmp(cmd, "record"))
        return pd_cmd_record(argc - 1, argv + 1);
    if (!strcmp(cmd, "bench"))
        return pd_cmd_bench(argc - 1, argv + 1);
    return pd_cli_usage_error("unknown command '%s' (try `pound --help`)", cmd);
}

/* Everything printed on standard output must have reached it: a write
 * error (a full disk, /dev/full) is a failure, exit 1 with the system's
 * reason, unless the command failed already.  When an earlier flush failed
 * (json.c flushes), its errno is the one still set, as nothing since has
 * failed. */
static int finish_stdout(int status)
{
    int before = errno, flushed = fflush(stdout) == 0, e = flushed ? before : errno;
    if (flushed && !ferror(stdout))
        return status;
    fprintf(stderr, "pound: standard output: %s\n", strerror(e ? e : EIO));
    return status ? status : 1;
}

int main(int argc, char **argv)
{
    pd_output_signals();
    return finish_stdout(dispatch(argc, argv));
}
