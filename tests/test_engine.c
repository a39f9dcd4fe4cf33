#include "pd_test.h"

void suite_engine(pd_test_ctx *ctx)
{
    (void)ctx;
}
