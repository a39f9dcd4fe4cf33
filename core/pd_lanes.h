/* pd_lanes.h — (library-private) the processor's own vector of doubles for
 * the batched kernels' texts (engine/pd_mj1_lanes.h, engine/mj_batch_lanes.h,
 * problems/osc_batch_lanes.h): 8 lanes under AVX-512, 4 under AVX2, 2 on
 * the baseline.  Include it after the file's `#pragma GCC target` (the
 * width follows the target's macros); generic vectors wider than the
 * registers were split by GCC through the stack on AVX2.
 *
 * Conditions (lcond) are the instruction set's own: AVX-512's mask
 * registers, AVX2's and SSE2's vectors of all-ones or zero lanes; a
 * selection is one blend where the instruction set has it.  The
 * comparisons are C's (<=, <, >, >=, ==: false when unordered), the
 * selections exact (no arithmetic on the values). */
#ifndef PD_LANES_H
#define PD_LANES_H

#if defined(__AVX512F__)
#define LW 8
#elif defined(__AVX__)
#define LW 4
#else
#define LW 2
#endif

/* The x86 instructions' forms below (PD_LANES_GENERIC: the generic vector
 * code everywhere, to check it on x86). */
#if defined(__x86_64__) && !defined(PD_LANES_GENERIC)
#define PD_LANES_X86 1
#else
#define PD_LANES_X86 0
#endif

typedef double lvec __attribute__((vector_size(8 * LW)));
typedef long long lmask __attribute__((vector_size(8 * LW))); /* all ones or zero */
/* a where the mask m is set, else b. */
#define LSELECT(m, a, b) ((lvec)(((m) & (lmask)(a)) | (~(m) & (lmask)(b))))

#if defined(__AVX512F__) && PD_LANES_X86
#include <immintrin.h>
typedef __mmask8 lcond;
#define LCMP_(a, b, p) _mm512_cmp_pd_mask((__m512d)(a), (__m512d)(b), p)
#define LLE(a, b) LCMP_(a, b, _CMP_LE_OS)
#define LLT(a, b) LCMP_(a, b, _CMP_LT_OS)
#define LGT(a, b) LCMP_(a, b, _CMP_GT_OS)
#define LGE(a, b) LCMP_(a, b, _CMP_GE_OS)
#define LEQ(a, b) LCMP_(a, b, _CMP_EQ_OQ)
/* a where c, else b */
#define LSEL(c, a, b) ((lvec)_mm512_mask_blend_pd(c, (__m512d)(b), (__m512d)(a)))
/* a where c, else +0 */
#define LKEEP(c, a) ((lvec)_mm512_maskz_mov_pd(c, (__m512d)(a)))
#define LCOND_OF(m) _mm512_test_epi64_mask((__m512i)(m), (__m512i)(m))
#else
typedef lmask lcond;
#define LLE(a, b) ((a) <= (b))
#define LLT(a, b) ((a) < (b))
#define LGT(a, b) ((a) > (b))
#define LGE(a, b) ((a) >= (b))
#define LEQ(a, b) ((a) == (b))
#if (defined(__AVX__) || defined(__SSE2__)) && PD_LANES_X86
#include <immintrin.h>
#endif
#if defined(__AVX__) && PD_LANES_X86
#define LSEL(c, a, b) ((lvec)_mm256_blendv_pd((__m256d)(b), (__m256d)(a), (__m256d)(c)))
#else
#define LSEL(c, a, b) LSELECT(c, a, b)
#endif
#define LKEEP(c, a) ((lvec)((c) & (lmask)(a)))
#define LCOND_OF(m) (m)
#endif

/* The lanes of the condition c as the bits of a whole number (lane i:
 * bit i). */
static inline unsigned lbits(lcond c)
{
#if defined(__AVX512F__) && PD_LANES_X86
    return (unsigned)c;
#elif defined(__AVX__) && PD_LANES_X86
    return (unsigned)_mm256_movemask_pd((__m256d)c);
#elif defined(__SSE2__) && PD_LANES_X86
    return (unsigned)_mm_movemask_pd((__m128d)c);
#else
    unsigned bits = 0;
    for (int i = 0; i < LW; i++)
        bits |= (c[i] != 0) << i;
    return bits;
#endif
}

#endif
