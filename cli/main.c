/* main.c — `pound`: dispatch to a subcommand. */
#include <string.h>

#include "pd_cli.h"
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

int main(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        fputs(usage, argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
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
