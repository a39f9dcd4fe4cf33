/* args.c — parsing flag values with errors that name the flag. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "pd_cli.h"

int pd_cli_usage_error(const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    pd_err_sanitize(msg); /* flags and file text may hold control bytes */
    fprintf(stderr, "pound: %s\n", msg);
    return 2;
}

int pd_cli_help(int argc, char **argv, const char *usage, int with_case)
{
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            fputs(usage, stdout);
            if (with_case)
                fputs(pd_cli_case_help, stdout);
            return 1;
        }
    return 0;
}

int pd_cli_double(const char *flag, const char *text, double *out)
{
    char *end = NULL;
    if (!text)
        return pd_cli_usage_error("%s needs a value", flag);
    errno = 0;
    double x = strtod(text, &end);
    if (end == text || *end != '\0')
        return pd_cli_usage_error("%s: '%s' is not a number", flag, text);
    if (errno == ERANGE) /* beyond the doubles, or below their normal range */
        return pd_cli_usage_error("%s: '%s' is out of range (a magnitude between 1e-307 and "
                                  "1e308, or 0)",
                                  flag, text);
    if (!isfinite(x))
        return pd_cli_usage_error("%s: '%s' is not a finite number", flag, text);
    *out = x;
    return 0;
}

int pd_cli_int(const char *flag, const char *text, int *out)
{
    char *end = NULL;
    if (!text)
        return pd_cli_usage_error("%s needs a value", flag);
    errno = 0;
    long x = strtol(text, &end, 10);
    if (end == text || *end != '\0' || errno == ERANGE || x < INT_MIN || x > INT_MAX)
        return pd_cli_usage_error("%s: '%s' is not an integer", flag, text);
    *out = (int)x;
    return 0;
}
