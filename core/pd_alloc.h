/* pd_alloc.h — (library-internal) the library's allocations, after
 * CSparse's cs_malloc: a count of zero or less asks for one element, so
 * that NULL means out of memory (or a size past SIZE_MAX) and nothing
 * else; the caller frees with free(). */
#ifndef PD_ALLOC_H
#define PD_ALLOC_H

#include <stdint.h>
#include <stdlib.h>

/* max(n, 1) elements of size bytes, uninitialised. */
static inline void *pd_malloc(long n, size_t size)
{
    size_t k = n > 0 ? (size_t)n : 1;
    return size && k > SIZE_MAX / size ? NULL : malloc(k * size);
}

/* max(n, 1) elements of size bytes, zeroed. */
static inline void *pd_calloc(long n, size_t size)
{
    return calloc(n > 0 ? (size_t)n : 1, size);
}

#endif
