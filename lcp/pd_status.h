/* pd_status.h — status codes and error messages shared by every pound module.
 *
 * Every library function that can fail returns an int status: 0 (PD_OK) on
 * success, a negative PD_E* code otherwise, and may fill a pd_err with a
 * one-line message naming what went wrong.  The library never prints, exits
 * or aborts; the caller decides what to show. */
#ifndef PD_STATUS_H
#define PD_STATUS_H

#include <stddef.h>

enum {
    PD_OK = 0,
    PD_ENOMEM = -1,      /* an allocation failed */
    PD_EINVAL = -2,      /* an argument is out of range or inconsistent */
    PD_ENOSOLUTION = -3, /* LCP: ray termination, the LCP may have no solution */
    PD_EMAXPIVOTS = -4,  /* LCP: pivot cap reached */
    PD_ENUMERICAL = -5,  /* pivot too small, lost precision, failed verification */
    PD_ENONFINITE = -6,  /* a NaN or infinity appeared in the state */
    PD_EIO = -7,         /* a file could not be opened, read or written */
    PD_EPARSE = -8,      /* a file is malformed */
    PD_ESINGULAR = -9,   /* a matrix to factor is singular */
    PD_EBUDGET = -10,    /* an event or step budget was exhausted */
    PD_ESTOPPED = -11    /* an observer asked the run to stop (not an error) */
};

/* A one-line error message; status mirrors the code returned. */
typedef struct pd_err {
    int status;
    char msg[256];
} pd_err;

/* Short text for a status code ("out of memory", ...). */
const char *pd_strerror(int status);

/* Record status and a printf-style message in err (err may be NULL);
 * returns status so callers can write `return pd_err_set(err, ...)`. */
int pd_err_set(pd_err *err, int status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Clear err to PD_OK with an empty message. */
void pd_err_clear(pd_err *err);

/* Monotonic wall-clock time, and the calling thread's CPU time, in seconds. */
double pd_wall_seconds(void);
double pd_cpu_seconds(void);

#endif
