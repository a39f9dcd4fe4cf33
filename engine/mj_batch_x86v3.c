/* mj_batch_x86v3.c — the batch's step compiled for x86-64-v3 (AVX2):
 * mj_batch_lanes.h's text; mj_batch.c picks it when the processor has it. */
#include "pd_mj1.h"

#if PD_X86_VARIANTS
#pragma GCC target("arch=x86-64-v3")
#define MJB_LANES_STEP pd_mjb_lanes_step_x86v3
#include "mj_batch_lanes.h"
#else
typedef int pd_mjb_x86v3_unused; /* nothing to compile here */
#endif
