#include "pd_test.h"

void suite_lcp(pd_test_ctx *ctx)
{
    (void)ctx;
}
