#include "pd_cli.h"

int pd_bench_engine(pd_json *js)
{
    (void)js;
    return 0;
}
