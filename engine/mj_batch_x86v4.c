/* mj_batch_x86v4.c — the batch's step compiled for x86-64-v4 (AVX-512):
 * mj_batch_lanes.h's text; mj_batch.c picks it when the processor has it. */
#include "pd_mj1.h"

#if PD_X86_VARIANTS
#pragma GCC target("arch=x86-64-v4")
#define MJB_LANES_STEP pd_mjb_lanes_step_x86v4
#include "mj_batch_lanes.h"
#else
typedef int pd_mjb_x86v4_unused; /* nothing to compile here */
#endif
