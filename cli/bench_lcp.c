#include "pd_cli.h"

int pd_bench_lcp(pd_json *js, const char *shared_dir)
{
    (void)js;
    (void)shared_dir;
    return 0;
}
