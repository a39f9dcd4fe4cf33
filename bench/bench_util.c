/* bench_util.c — what the drivers of `pound bench` share (pd_bench.h): the
 * machine they run on, printed once before them; the two clocks; medians;
 * the log-log slopes of the growth exponents. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pd_bench.h"
#include "pd_cpu.h"

pd_bench_clock pd_bench_now(void)
{
    pd_bench_clock t = {.wall_s = pd_wall_seconds(), .cpu_s = pd_cpu_seconds()};
    return t;
}

pd_bench_clock pd_bench_since(pd_bench_clock t0)
{
    pd_bench_clock t = pd_bench_now();
    t.wall_s -= t0.wall_s;
    t.cpu_s -= t0.cpu_s;
    return t;
}

int pd_bench_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double pd_bench_median(double *x, int n)
{
    if (n <= 0)
        return NAN;
    qsort(x, (size_t)n, sizeof *x, pd_bench_cmp_double);
    return n % 2 ? x[n / 2] : 0.5 * (x[n / 2 - 1] + x[n / 2]);
}

const char *pd_bench_cpu_model(char *buf, size_t size)
{
    FILE *f = fopen("/proc/cpuinfo", "r");
    char line[512];
    snprintf(buf, size, "unknown");
    if (!f)
        return buf;
    while (fgets(line, sizeof line, f)) {
        char *colon = strchr(line, ':');
        if (strncmp(line, "model name", 10) || !colon)
            continue;
        char *v = colon + 1;
        v += strspn(v, " \t");
        size_t len = strcspn(v, "\n");
        while (len > 0 && (v[len - 1] == ' ' || v[len - 1] == '\t'))
            len--;
        if (len > 0)
            snprintf(buf, size, "%.*s", (int)len, v);
        break;
    }
    fclose(f);
    return buf;
}

int pd_bench_machine(pd_json *js)
{
    char model[256];
    const char *isa_env = getenv("POUND_ISA");
    int level = pd_cpu_level();
    pd_bench_cpu_model(model, sizeof model);
    if (js) {
        pd_json_begin_object(js, "machine");
        pd_json_str(js, "processor", model);
        pd_json_str(js, "isa", pd_cpu_level_name(level));
        pd_json_int(js, "isa_level", level);
        if (isa_env)
            pd_json_str(js, "pound_isa", isa_env);
        else
            pd_json_null(js, "pound_isa");
        pd_json_str(js, "cpu_clock", "CLOCK_THREAD_CPUTIME_ID");
        pd_json_end_object(js);
    } else {
        printf("processor: %s; vector kernels: %s%s%s%s\n", model, pd_cpu_level_name(level),
               isa_env ? " (POUND_ISA=" : "", isa_env ? isa_env : "", isa_env ? ")" : "");
        printf("times: wall clock and CPU (the thread's, CLOCK_THREAD_CPUTIME_ID; on several "
               "threads, the sum of theirs)\n\n");
    }
    return 0;
}

void pd_loglog_add(pd_loglog_fit *f, double x, double y)
{
    double lx = log(x), ly = log(y);
    f->sx += lx;
    f->sy += ly;
    f->sxx += lx * lx;
    f->sxy += lx * ly;
    f->k++;
}

double pd_loglog_slope(const pd_loglog_fit *f)
{
    if (f->k < 2)
        return NAN;
    return (f->k * f->sxy - f->sx * f->sy) / (f->k * f->sxx - f->sx * f->sx);
}
