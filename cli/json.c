/* json.c — a streaming JSON writer (numbers printed to round-trip). */
#include <math.h>

#include "pd_cli.h"

void pd_json_init(pd_json *js, FILE *out)
{
    js->out = out;
    js->depth = 0;
    js->need_comma[0] = 0;
}

/* Comma and key before a member. */
static void member(pd_json *js, const char *key)
{
    if (js->need_comma[js->depth])
        fputc(',', js->out);
    js->need_comma[js->depth] = 1;
    if (key) {
        fputc('"', js->out);
        for (const char *c = key; *c; c++) {
            if (*c == '"' || *c == '\\')
                fputc('\\', js->out);
            fputc(*c, js->out);
        }
        fputs("\":", js->out);
    }
}

static void open(pd_json *js, const char *key, char bracket)
{
    member(js, key);
    fputc(bracket, js->out);
    if (js->depth < 31)
        js->depth++;
    js->need_comma[js->depth] = 0;
}

static void close_(pd_json *js, char bracket)
{
    if (js->depth > 0)
        js->depth--;
    fputc(bracket, js->out);
}

void pd_json_begin_object(pd_json *js, const char *key)
{
    open(js, key, '{');
}
void pd_json_end_object(pd_json *js)
{
    close_(js, '}');
}
void pd_json_begin_array(pd_json *js, const char *key)
{
    open(js, key, '[');
}
void pd_json_end_array(pd_json *js)
{
    close_(js, ']');
}

void pd_json_num(pd_json *js, const char *key, double x)
{
    member(js, key);
    if (isfinite(x))
        fprintf(js->out, "%.17g", x);
    else
        fputs("null", js->out);
}

void pd_json_int(pd_json *js, const char *key, long x)
{
    member(js, key);
    fprintf(js->out, "%ld", x);
}

void pd_json_str(pd_json *js, const char *key, const char *s)
{
    member(js, key);
    fputc('"', js->out);
    for (const unsigned char *c = (const unsigned char *)s; *c; c++) {
        if (*c == '"' || *c == '\\')
            fprintf(js->out, "\\%c", *c);
        else if (*c < 0x20)
            fprintf(js->out, "\\u%04x", *c);
        else
            fputc(*c, js->out);
    }
    fputc('"', js->out);
}

void pd_json_bool(pd_json *js, const char *key, int b)
{
    member(js, key);
    fputs(b ? "true" : "false", js->out);
}

void pd_json_null(pd_json *js, const char *key)
{
    member(js, key);
    fputs("null", js->out);
}

void pd_json_stats(pd_json *js, const char *key, const pd_stats *st)
{
    pd_json_begin_object(js, key);
    pd_json_int(js, "n", st->n);
    pd_json_num(js, "mean", st->mean);
    pd_json_num(js, "median", st->median);
    pd_json_num(js, "p16", st->p16);
    pd_json_num(js, "p84", st->p84);
    pd_json_num(js, "min", st->min);
    pd_json_num(js, "max", st->max);
    pd_json_end_object(js);
}

void pd_json_nums(pd_json *js, const char *key, int n, const double *x)
{
    pd_json_begin_array(js, key);
    for (int i = 0; i < n; i++)
        pd_json_num(js, NULL, x[i]);
    pd_json_end_array(js);
}

void pd_json_finish(pd_json *js)
{
    fputc('\n', js->out);
    fflush(js->out);
}
