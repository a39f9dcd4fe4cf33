/* api_fixtures.h -- live objects for the generated C API test
 * (tests/test_api_null.c, scripts/gen_api_null.py). */
#ifndef API_FIXTURES_H
#define API_FIXTURES_H

#include <stddef.h>
#include <string.h>

#include "pd_problems.h"

/* What a case expects of its call (see scripts/gen_api_null.py). */
typedef enum {
    EXPECT_ERROR = 0, /* an int status < 0 */
    EXPECT_COUNT,     /* an int count, flag or index <= 0 */
    EXPECT_NULL,      /* a NULL pointer */
    EXPECT_NAME,      /* a readable string (or NULL) */
    EXPECT_NOCRASH    /* returns, no sanitizer report */
} api_null_expect;

typedef struct api_null_case {
    const char *function, *argument;
    api_null_expect expect;
    long (*call)(void); /* the call's value (pointers: 1 when not NULL) */
} api_null_case;

extern const api_null_case api_null_cases[];
extern const int api_null_ncases, api_null_nfunctions;

/* A live object of the named public type for argument k of fn (a finished
 * scene, an allocated solver, default options, ...), or 1 MiB of zeros for
 * a plain array or a type without a fixture.  Never NULL (exits 99 when
 * out of memory: the case then fails as "not run"). */
void *fx_object(const char *type, const char *fn, int k);
/* A string for argument `name` of fn: a readable file for paths. */
const char *fx_string(const char *fn, const char *name);
/* A zeroed pointer-sized slot (for T **out arguments). */
void *fx_slot(void);

#endif
