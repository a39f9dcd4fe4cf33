#include "pd_cli.h"

int pd_cmd_simulate(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    return pd_cli_usage_error("simulate: not built yet");
}
