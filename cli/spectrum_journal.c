/* spectrum_journal.c — OUT.partial: an append-only record of the finished
 * tasks of a sweep, so that an interrupted sweep resumes where it stopped.
 *
 *   pound-spectrum-journal 1
 *   key <the canonical key of the sweep (pd_spec_key)>
 *   T <task> <umax> <u_toward> <u_away> <contact_time> <first_impact> <impacts> <steps> <cpu_s> #<fnv1a>
 *   T ... <cpu_s> Y <ductility> <residual> #<fnv1a>      (a yielding sweep's)
 *
 * Doubles are written in C99 hexadecimal, so a resumed sweep reads back
 * exactly the bits it computed.  The file's handling (one write a line,
 * checksums, a torn tail dropped, the lock, fdatasync) is journal.c's.
 * A journal this run created is
 * open write-only, one it resumed read-write: a sweep that ends as bad input
 * removes the first kind only (spectrum_run.c).  A signal leaves the
 * journal in place, so the sweep resumes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pd_spectrum.h"

static const pd_journal_kind spectrum_journal = {
    .magic = "pound-spectrum-journal 1\n", .flag = "-o", .what = "spectrum", .run = "sweep"};

/* One record's body into buf; its length, or -1 when it does not fit. */
static int format_record(char *buf, size_t cap, long task, const pd_spec_result *r)
{
    int n = snprintf(buf, cap, "T %ld %a %a %a %a %a %ld %ld %a", task, r->umax, r->u_toward,
                     r->u_away, r->contact_time, r->first_impact, r->impacts, r->steps, r->cpu_s);
    if (n >= 0 && (size_t)n < cap && !isnan(r->ductility)) /* a yielding run's figures */
        n += snprintf(buf + n, cap - (size_t)n, " Y %a %a", r->ductility, r->residual);
    return n < 0 || (size_t)n >= cap ? -1 : n;
}

/* Where the records read back go. */
typedef struct spec_load {
    long ntasks, *loaded;
    pd_spec_result *res;
} spec_load;

/* Parse one record's body (its checksum checked): 0, or -1 when malformed. */
static int parse_record(const char *line, size_t len, void *ctx)
{
    spec_load *l = ctx;
    char buf[512], *p, *end;
    pd_spec_result r;
    if (len >= sizeof buf || len < 4 || line[0] != 'T')
        return -1;
    memcpy(buf, line, len);
    buf[len] = '\0';
    memset(&r, 0, sizeof r);
    long task = strtol(buf + 1, &p, 10);
    double *d[] = {&r.umax, &r.u_toward, &r.u_away, &r.contact_time, &r.first_impact};
    for (int i = 0; i < 5; i++)
        *d[i] = strtod(p, &p);
    r.impacts = strtol(p, &p, 10);
    r.steps = strtol(p, &p, 10);
    r.cpu_s = strtod(p, &end);
    r.ductility = r.residual = NAN;
    int bad = end == p;
    if (!bad && !strncmp(end, " Y ", 3)) { /* a yielding run's figures */
        p = end + 3;
        r.ductility = strtod(p, &p);
        r.residual = strtod(p, &end);
        bad = end == p;
    }
    r.done = 1;
    if (bad || task < 0 || task >= l->ntasks)
        return -1;
    *l->loaded += !l->res[task].done;
    l->res[task] = r;
    return 0;
}

int pd_spec_journal_open(pd_spec_journal *j, const char *out, const char *key, long ntasks,
                         int resume, pd_spec_result *res, long *loaded, pd_err *err)
{
    char path[sizeof j->path];
    spec_load l = {.ntasks = ntasks, .loaded = loaded, .res = res};
    *loaded = 0;
    if (snprintf(path, sizeof path, "%s.partial", out) >= (int)sizeof path) {
        memset(j, 0, sizeof *j);
        j->fd = -1;
        return pd_err_set(err, PD_EINVAL, "-o %s: path too long", out);
    }
    return pd_journal_open(j, &spectrum_journal, path, key, resume, parse_record, &l, err);
}

int pd_spec_journal_append(pd_spec_journal *j, long task, const pd_spec_result *r)
{
    char body[512];
    int n = format_record(body, sizeof body, task, r);
    if (n < 0) {
        j->failed = 1;
        return -1;
    }
    return pd_journal_append(j, body, (size_t)n);
}

void pd_spec_journal_close(pd_spec_journal *j, int remove)
{
    pd_journal_close(j, remove);
}
