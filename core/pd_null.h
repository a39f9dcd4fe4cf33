/* pd_null.h -- private: the library's answer to a NULL it cannot use.
 *
 * Every exported function checks each pointer it is given (docs/api.md,
 * "Pointers"; tests/test_api_null.c is generated from the public headers):
 * a status-returning one returns PD_NULL_ARG(err, "name"), "fn: name is
 * NULL" as PD_EINVAL; one returning a pointer returns NULL, a value NAN or 0,
 * and a void one does nothing. */
#ifndef PD_NULL_H
#define PD_NULL_H

#include "pd_core.h"

#define PD_NULL_ARG(err, name) pd_err_set((err), PD_EINVAL, "%s: %s is NULL", __func__, (name))

/* The caller's pd_err, or local when it passed none: a failure's status is
 * then read back from it, never guessed. */
static inline pd_err *pd_err_or(pd_err *err, pd_err *local)
{
    if (err)
        return err;
    pd_err_clear(local);
    return local;
}

#endif
