/* osc_batch_x86v3.c — the batch's measurements compiled for x86-64-v3
 * (AVX2): osc_batch_lanes.h's text; osc_batch.c picks it when the
 * processor has it. */
#include "osc_batch.h"

#if PD_X86_VARIANTS
#pragma GCC target("arch=x86-64-v3")
#define OSC_BATCH_RUN pd_osc_batch_run_x86v3
#include "osc_batch_lanes.h"
#else
typedef int pd_osc_batch_x86v3_unused; /* nothing to compile here */
#endif
