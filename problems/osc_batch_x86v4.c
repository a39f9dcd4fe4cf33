/* osc_batch_x86v4.c — the batch's measurements compiled for x86-64-v4
 * (AVX-512): osc_batch_lanes.h's text; osc_batch.c picks it when the
 * processor has it. */
#include "osc_batch.h"

#if PD_X86_VARIANTS
#pragma GCC target("arch=x86-64-v4")
#define OSC_BATCH_RUN pd_osc_batch_run_x86v4
#include "osc_batch_lanes.h"
#else
typedef int pd_osc_batch_x86v4_unused; /* nothing to compile here */
#endif
