#include "pd_cli.h"

int pd_cmd_lcp(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    return pd_cli_usage_error("lcp: not built yet");
}
