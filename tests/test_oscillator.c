#include "pd_test.h"

void suite_oscillator(pd_test_ctx *ctx)
{
    (void)ctx;
}
