/* bench_startup.c — `pound bench --startup`: what a process costs before
 * it computes.  `pound simulate --json` (the exact reference, two runs of
 * about 0.2 ms) and `pound --version` are spawned 50 times each, beside the
 * smallest process there is (/bin/true), wall time per process and the
 * CPU time it used (user + system of the waited-for children, getrusage;
 * the median of five rounds each); and the shared libraries this process
 * mapped at start (HDF5 and CHOLMOD are loaded only when a run needs them:
 * cli/lazy.c). */
#include <math.h>
#include <fcntl.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "pd_bench.h"

extern char **environ;

/* The CPU seconds (user + system) of the waited-for children so far. */
static double children_cpu(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_CHILDREN, &ru))
        return NAN;
    return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
           (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
}

/* Wall seconds per process of argv spawned n times (stdout to /dev/null),
 * and the CPU seconds each used (*cpu): the median of five rounds each;
 * NAN when a spawn fails. */
static double per_process(char *const argv[], int n, double *cpu)
{
    double round[5], cpu_round[5];
    *cpu = NAN;
    posix_spawn_file_actions_t fa;
    if (posix_spawn_file_actions_init(&fa) ||
        posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0))
        return NAN;
    for (int r = 0; r < 5; r++) {
        double t0 = pd_wall_seconds(), c0 = children_cpu();
        for (int k = 0; k < n; k++) {
            pid_t pid;
            int st;
            if (posix_spawn(&pid, argv[0], &fa, NULL, argv, environ) ||
                waitpid(pid, &st, 0) != pid || !WIFEXITED(st) || WEXITSTATUS(st)) {
                posix_spawn_file_actions_destroy(&fa);
                return NAN;
            }
        }
        round[r] = (pd_wall_seconds() - t0) / n;
        cpu_round[r] = (children_cpu() - c0) / n;
    }
    posix_spawn_file_actions_destroy(&fa);
    *cpu = pd_bench_median(cpu_round, 5);
    return pd_bench_median(round, 5);
}

/* Shared objects mapped by this process (distinct paths ending in .so*). */
static int mapped_libraries(void)
{
    FILE *f = fopen("/proc/self/maps", "r");
    char line[1024], seen[64][256];
    int n = 0;
    if (!f)
        return -1;
    while (fgets(line, sizeof line, f)) {
        char *path = strchr(line, '/');
        if (!path || !strstr(path, ".so"))
            continue;
        path[strcspn(path, "\n")] = '\0';
        int dup = 0;
        for (int k = 0; k < n && !dup; k++)
            dup = !strcmp(seen[k], path);
        if (!dup && n < 64)
            snprintf(seen[n++], sizeof seen[0], "%s", path);
    }
    fclose(f);
    return n;
}

int pd_bench_startup(pd_json *js)
{
    char self[4096];
    ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
    if (len <= 0)
        return 1;
    self[len] = '\0';
    int libs = mapped_libraries();
    char *sim[] = {self, "simulate", "--json", NULL}, *ver[] = {self, "--version", NULL};
    char *tru[] = {"/bin/true", NULL};
    double c_true, c_ver, c_sim;
    double t_true = per_process(tru, 50, &c_true), t_ver = per_process(ver, 50, &c_ver);
    double t_sim = per_process(sim, 50, &c_sim);
    if (js) {
        pd_json_begin_object(js, "startup");
        pd_json_num(js, "true_ms", 1e3 * t_true);
        pd_json_num(js, "version_ms", 1e3 * t_ver);
        pd_json_num(js, "simulate_json_ms", 1e3 * t_sim);
        pd_json_num(js, "true_cpu_ms", 1e3 * c_true);
        pd_json_num(js, "version_cpu_ms", 1e3 * c_ver);
        pd_json_num(js, "simulate_json_cpu_ms", 1e3 * c_sim);
        pd_json_int(js, "shared_libraries", libs);
        pd_json_num(js, "target_simulate_json_ms", 5.0);
        pd_json_end_object(js);
    } else {
        printf("Start-up (wall time per process, and the CPU time it used: user + system; 50 "
               "spawns, median of 5 rounds)\n");
        printf("  /bin/true                 %7.2f ms  CPU %5.2f ms   (the smallest process here)\n",
               1e3 * t_true, 1e3 * c_true);
        printf("  pound --version           %7.2f ms  CPU %5.2f ms   (%.2f ms more)\n", 1e3 * t_ver,
               1e3 * c_ver, 1e3 * (t_ver - t_true));
        printf("  pound simulate --json     %7.2f ms  CPU %5.2f ms   (%.2f ms more; two exact runs "
               "of ~0.2 ms; target 5 ms)\n",
               1e3 * t_sim, 1e3 * c_sim, 1e3 * (t_sim - t_true));
        printf("  shared libraries mapped at start: %d (HDF5 and CHOLMOD load when a run "
               "needs them)\n",
               libs);
    }
    return isfinite(t_sim) && isfinite(t_ver) ? 0 : 1;
}
