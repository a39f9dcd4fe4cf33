/* main.c — `pound`: dispatch to a subcommand, `pound help COMMAND` and
 * `pound --version`; temporary output files removed on SIGINT/SIGTERM;
 * standard output checked at the end. */
#include <cholmod.h>
#include <errno.h>
#include <gsl/gsl_version.h>
#include <hdf5.h>
#include <jansson.h>
#include <stdlib.h>
#include <string.h>

#include "pd_cli.h"
#include "pd_cpu.h"
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
    "  bench      performance figures (--lcp, --engine, --scene, --spectrum, --records, "
    "--startup)\n"
    "  help CMD   the options of a command (as `pound CMD --help`)\n"
    "\n"
    "  --version  pound's version and the libraries it was built with\n"
    "\n"
    "`pound <command> --help` lists a command's options (a value after the flag, or\n"
    "--flag=value); man pound and docs/ have the details.\n";

/* The commands and their entry points. */
static const struct {
    const char *name;
    int (*run)(int argc, char **argv);
} commands[] = {{"simulate", pd_cmd_simulate}, {"compare", pd_cmd_compare},
                {"converge", pd_cmd_converge}, {"spectrum", pd_cmd_spectrum},
                {"record", pd_cmd_record},     {"lcp", pd_cmd_lcp},
                {"bench", pd_cmd_bench}};

#define NCOMMANDS (int)(sizeof commands / sizeof commands[0])

/* The command called name, or -1. */
static int find_command(const char *name)
{
    for (int k = 0; k < NCOMMANDS; k++)
        if (!strcmp(commands[k].name, name))
            return k;
    return -1;
}

/* `pound --version`: this program's version (and the library's, when a
 * shared libpound of another version answers), then what it was built with. */
static int version(void)
{
    printf("pound %s", PD_VERSION);
    if (strcmp(pd_version(), PD_VERSION))
        printf(" (libpound %s)", pd_version());
    printf("\nbuilt with GSL %s, HDF5 %d.%d.%d, jansson %s, CHOLMOD %d.%d.%d", GSL_VERSION,
           H5_VERS_MAJOR, H5_VERS_MINOR, H5_VERS_RELEASE, JANSSON_VERSION, CHOLMOD_MAIN_VERSION,
           CHOLMOD_SUB_VERSION, CHOLMOD_SUBSUB_VERSION);
#ifdef _OPENMP
    printf(", OpenMP %d", _OPENMP);
#endif
#ifdef PD_MPI
    printf(", MPI");
#endif
    printf("\n");
    return 0;
}

/* `pound help [COMMAND]`: the command's --help (exit 0), the usage without
 * one; an unknown command is bad input (exit 2). */
static int help(int argc, char **argv)
{
    if (argc < 3) {
        fputs(usage, stdout);
        return 0;
    }
    if (argc > 3)
        return pd_cli_usage_error("help: one command at a time (got '%s' after '%s')", argv[3],
                                  argv[2]);
    int k = find_command(argv[2]);
    if (k < 0)
        return pd_cli_usage_error("help: unknown command '%s' (simulate, compare, converge, "
                                  "spectrum, record, lcp or bench)",
                                  argv[2]);
    char flag[] = "--help", *av[] = {argv[2], flag, NULL};
    return commands[k].run(2, av);
}

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
    if (!strcmp(argv[1], "--version"))
        return version();
    const char *cmd = argv[1];
    if (!strcmp(cmd, "help"))
        return help(argc, argv);
    int k = find_command(cmd);
    const char *isa = getenv("POUND_ISA");
    if (k >= 0 && isa && pd_cpu_isa_parse(isa) < 0)
        return pd_cli_usage_error("POUND_ISA='%s': the vector kernels' instruction set must be "
                                  "baseline, avx2 or avx512 (or unset)",
                                  isa);
    if (k >= 0)
        return commands[k].run(argc - 1, argv + 1);
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

/* Every "--flag=value" token as "--flag" "value" (getopt_long's form, which
 * the commands read as two tokens): the '=' ends the flag in place and the
 * value follows it in a new argument vector (*out, to free; NULL when none
 * needed splitting or out of memory: argv as given). */
static char **split_equals(int argc, char **argv, int *out_argc)
{
    int extra = 0;
    for (int i = 1; i < argc; i++) /* a flag's name before the '=' */
        extra += !strncmp(argv[i], "--", 2) && strchr(argv[i] + 2, '=') > argv[i] + 2;
    char **av = extra ? malloc(((size_t)argc + (size_t)extra + 1) * sizeof *av) : NULL;
    if (!av)
        return NULL;
    int n = 0;
    for (int i = 0; i < argc; i++) {
        char *eq = i > 0 && !strncmp(argv[i], "--", 2) ? strchr(argv[i] + 2, '=') : NULL;
        av[n++] = argv[i];
        if (eq && eq > argv[i] + 2) {
            *eq = '\0';
            av[n++] = eq + 1;
        }
    }
    av[n] = NULL;
    *out_argc = n;
    return av;
}

int main(int argc, char **argv)
{
    /* CHOLMOD's BLAS on the calling thread (unless the user says): its
     * factors here are banded and small per column, and OpenBLAS's worker
     * threads spin between calls and, out of memory, retry their buffers
     * forever while exit waits for them */
    setenv("OPENBLAS_NUM_THREADS", "1", 0);
    pd_output_signals();
    int n = argc;
    char **av = split_equals(argc, argv, &n);
    int status = finish_stdout(dispatch(av ? n : argc, av ? av : argv));
    free(av);
    return status;
}
