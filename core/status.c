/* status.c — status codes, error messages and clocks. */
#include "pd_core.h"

#include <stdarg.h>
#include <stdio.h>
#include <time.h>

const char *pd_strerror(int status)
{
    switch (status) {
    case PD_OK:
        return "ok";
    case PD_ENOMEM:
        return "out of memory";
    case PD_EINVAL:
        return "invalid argument";
    case PD_ENOSOLUTION:
        return "no solution (ray termination)";
    case PD_EMAXPIVOTS:
        return "pivot limit reached";
    case PD_ENUMERICAL:
        return "numerical failure";
    case PD_ENONFINITE:
        return "non-finite value";
    case PD_EIO:
        return "input/output error";
    case PD_EPARSE:
        return "malformed input";
    case PD_ESINGULAR:
        return "singular matrix";
    case PD_EBUDGET:
        return "budget exhausted";
    case PD_ESTOPPED:
        return "stopped by observer";
    case PD_EMAXITER:
        return "iteration limit reached";
    default:
        return "unknown status";
    }
}

/* Control bytes (a newline, an escape sequence from a file) shown as '?':
 * a message is one line of text whatever it quotes. */
void pd_err_sanitize(char *msg)
{
    if (!msg)
        return;
    for (; *msg; msg++)
        if ((unsigned char)*msg < 0x20 || *msg == 0x7f)
            *msg = '?';
}

int pd_err_set(pd_err *err, int status, const char *fmt, ...)
{
    if (err && !fmt) {
        err->status = status;
        snprintf(err->msg, sizeof err->msg, "%s", pd_strerror(status));
    } else if (err) {
        va_list ap;
        err->status = status;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
        pd_err_sanitize(err->msg);
    }
    return status;
}

void pd_err_clear(pd_err *err)
{
    if (err) {
        err->status = PD_OK;
        err->msg[0] = '\0';
    }
}

double pd_wall_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* CPU time of the calling thread (a run's cost, also under OpenMP). */
double pd_cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

const char *pd_version(void)
{
    return PD_VERSION;
}
