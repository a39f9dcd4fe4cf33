/* pd_lanes.h — (library-private) the processor's own vector of doubles for
 * the batched kernels' texts (engine/mj_batch_lanes.h,
 * problems/osc_batch_lanes.h): 8 lanes under AVX-512, 4 under AVX2, 2 on
 * the baseline.  Include it after the file's `#pragma GCC target` (the
 * width follows the target's macros); generic vectors wider than the
 * registers were split by GCC through the stack on AVX2. */
#ifndef PD_LANES_H
#define PD_LANES_H

#if defined(__AVX512F__)
#define LW 8
#elif defined(__AVX__)
#define LW 4
#else
#define LW 2
#endif

typedef double lvec __attribute__((vector_size(8 * LW)));
typedef long long lmask __attribute__((vector_size(8 * LW))); /* all ones or zero */
/* a where the mask m is set, else b. */
#define LSELECT(m, a, b) ((lvec)(((m) & (lmask)(a)) | (~(m) & (lmask)(b))))

#endif
