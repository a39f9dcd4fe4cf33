#include "pd_test.h"

void suite_cli(pd_test_ctx *ctx)
{
    (void)ctx;
}
