/* spectrum_journal.c — OUT.partial: an append-only record of the finished
 * tasks of a sweep, so that an interrupted sweep resumes where it stopped.
 *
 *   pound-spectrum-journal 1
 *   key <the canonical key of the sweep (pd_spec_key)>
 *   T <task> <umax> <u_toward> <u_away> <contact_time> <first_impact> <impacts> <steps> <cpu_s> #<fnv1a>
 *   T ... <cpu_s> Y <ductility> <residual> #<fnv1a>      (a yielding sweep's)
 *
 * Doubles are written in C99 hexadecimal, so a resumed sweep reads back
 * exactly the bits it computed.  Each record is one write(2) on an
 * O_APPEND descriptor: a killed process leaves whole lines and at worst one
 * torn last line, which the checksum exposes and the reader drops.
 * fdatasync runs at most once a second (an OS crash loses at most that
 * much work; a killed process loses nothing written).  A POSIX record lock
 * keeps two sweeps from sharing one journal.  A journal this run created is
 * open write-only, one it resumed read-write: a sweep that ends as bad input
 * removes the first kind only (spectrum_run.c).  A signal leaves the
 * journal in place, so the sweep resumes. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pd_spectrum.h"

static const char magic[] = "pound-spectrum-journal 1\n";

/* FNV-1a hash of n bytes (the record checksum). */
static uint32_t fnv1a(const char *p, size_t n)
{
    uint32_t h = 2166136261u;
    for (size_t i = 0; i < n; i++) {
        h ^= (unsigned char)p[i];
        h *= 16777619u;
    }
    return h;
}

/* One record line into buf; its length, or -1 when it does not fit. */
static int format_record(char *buf, size_t cap, long task, const pd_spec_result *r)
{
    int n = snprintf(buf, cap, "T %ld %a %a %a %a %a %ld %ld %a", task, r->umax, r->u_toward,
                     r->u_away, r->contact_time, r->first_impact, r->impacts, r->steps, r->cpu_s);
    if (n >= 0 && (size_t)n < cap && !isnan(r->ductility)) /* a yielding run's figures */
        n += snprintf(buf + n, cap - (size_t)n, " Y %a %a", r->ductility, r->residual);
    if (n < 0 || (size_t)n >= cap)
        return -1;
    int m = snprintf(buf + n, cap - (size_t)n, " #%08lx\n", (unsigned long)fnv1a(buf, (size_t)n));
    return m < 0 || (size_t)(n + m) >= cap ? -1 : n + m;
}

/* Parse one record line (without its newline): 0, or -1 when malformed. */
static int parse_record(const char *line, size_t len, long ntasks, long *task, pd_spec_result *r)
{
    char buf[512], *p, *end;
    const char *hash = NULL;
    for (size_t i = len; i-- > 0;)
        if (line[i] == '#') {
            hash = line + i;
            break;
        }
    if (len >= sizeof buf || len < 4 || line[0] != 'T' || !hash || hash == line || hash[-1] != ' ')
        return -1;
    if (strtoul(hash + 1, &end, 16) != fnv1a(line, (size_t)(hash - 1 - line)) || end != line + len)
        return -1;
    memcpy(buf, line, (size_t)(hash - line));
    buf[hash - line] = '\0';
    memset(r, 0, sizeof *r);
    *task = strtol(buf + 1, &p, 10);
    double *d[] = {&r->umax, &r->u_toward, &r->u_away, &r->contact_time, &r->first_impact};
    for (int i = 0; i < 5; i++)
        *d[i] = strtod(p, &p);
    r->impacts = strtol(p, &p, 10);
    r->steps = strtol(p, &p, 10);
    r->cpu_s = strtod(p, &end);
    r->ductility = r->residual = NAN;
    int bad = end == p;
    if (!bad && !strncmp(end, " Y ", 3)) { /* a yielding run's figures */
        p = end + 3;
        r->ductility = strtod(p, &p);
        r->residual = strtod(p, &end);
        bad = end == p;
    }
    r->done = 1;
    return bad || *task < 0 || *task >= ntasks ? -1 : 0;
}

/* An exclusive lock on the whole file, released when the process ends. */
static int lock_fd(int fd)
{
    struct flock fl;
    memset(&fl, 0, sizeof fl);
    fl.l_type = F_WRLCK;
    fl.l_whence = SEEK_SET;
    return fcntl(fd, F_SETLK, &fl);
}

/* Write all of buf: 0 or -1. */
static int write_all(int fd, const char *buf, size_t n)
{
    while (n > 0) {
        ssize_t w = write(fd, buf, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return -1;
        buf += w;
        n -= (size_t)w;
    }
    return 0;
}

/* A fresh journal with its header (it must not exist yet). */
static int create_journal(pd_spec_journal *j, const char *key, pd_err *err)
{
    j->fd = open(j->path, O_WRONLY | O_CREAT | O_EXCL | O_APPEND, 0644);
    if (j->fd < 0 && errno == EEXIST)
        return pd_err_set(err, PD_EINVAL,
                          "-o: %s exists: an interrupted sweep; add --resume to continue it, or "
                          "delete it",
                          j->path);
    if (j->fd < 0)
        return pd_err_set(err, PD_EIO, "-o: cannot create %s: %s", j->path, strerror(errno));
    if (lock_fd(j->fd) || write_all(j->fd, magic, strlen(magic)) || write_all(j->fd, "key ", 4) ||
        write_all(j->fd, key, strlen(key)) || write_all(j->fd, "\n", 1) || fdatasync(j->fd)) {
        int e = errno ? errno : EIO;
        close(j->fd);
        j->fd = -1;
        unlink(j->path);
        return pd_err_set(err, PD_EIO, "-o: cannot write %s: %s", j->path, strerror(e));
    }
    return PD_OK;
}

/* Read the whole file into a NUL-terminated buffer (NULL on failure). */
static char *read_fd(int fd, size_t *len)
{
    struct stat st;
    if (fstat(fd, &st) != 0)
        return NULL;
    char *buf = malloc((size_t)st.st_size + 1);
    size_t n = 0;
    while (buf && n < (size_t)st.st_size) {
        ssize_t r = pread(fd, buf + n, (size_t)st.st_size - n, (off_t)n);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            break;
        n += (size_t)r;
    }
    if (buf)
        buf[n] = '\0';
    *len = n;
    return buf;
}

/* The first "name=" token whose value differs between two keys. */
static void first_difference(const char *a, const char *b, char *name, size_t cap)
{
    snprintf(name, cap, "a parameter");
    while (*a && *b) {
        size_t la = strcspn(a, " "), lb = strcspn(b, " ");
        if (la != lb || memcmp(a, b, la)) {
            size_t k = strcspn(b, "= ");
            snprintf(name, cap, "--%.*s", (int)(k < 60 ? k : 60), b);
            return;
        }
        a += la + (a[la] == ' ');
        b += lb + (b[lb] == ' ');
    }
}

/* Check the header lines against key: 0, or PD_EINVAL naming what differs. */
static int check_header(const pd_spec_journal *j, const char *buf, const char *key, size_t *body,
                        pd_err *err)
{
    size_t lm = strlen(magic), lk = strlen(key);
    char what[80];
    if (strncmp(buf, magic, lm) || strncmp(buf + lm, "key ", 4))
        return pd_err_set(err, PD_EINVAL, "--resume: %s is not a pound spectrum journal", j->path);
    const char *k = buf + lm + 4, *nl = strchr(k, '\n');
    if (!nl || (size_t)(nl - k) != lk || memcmp(k, key, lk)) {
        char *old = nl ? strndup(k, (size_t)(nl - k)) : NULL;
        first_difference(old ? old : "", key, what, sizeof what);
        free(old);
        return pd_err_set(err, PD_EINVAL,
                          "--resume: %s belongs to a different sweep (%s differs); repeat that "
                          "sweep's flags or delete it",
                          j->path, what);
    }
    *body = (size_t)(nl + 1 - buf);
    return PD_OK;
}

/* Records after the header; a torn tail (no newline) is cut off the file. */
static int load_records(pd_spec_journal *j, const char *buf, size_t len, size_t pos, long ntasks,
                        pd_spec_result *res, long *loaded)
{
    long t;
    pd_spec_result r;
    while (pos < len) {
        const char *nl = memchr(buf + pos, '\n', len - pos);
        if (!nl)
            return ftruncate(j->fd, (off_t)pos);
        if (!parse_record(buf + pos, (size_t)(nl - buf - pos), ntasks, &t, &r)) {
            *loaded += !res[t].done;
            res[t] = r;
        }
        pos = (size_t)(nl + 1 - buf);
    }
    return 0;
}

/* Reopen an existing journal (or start one): its finished tasks into res. */
static int resume_journal(pd_spec_journal *j, const char *key, long ntasks, pd_spec_result *res,
                          long *loaded, pd_err *err)
{
    size_t len = 0, body = 0;
    int rc;
    j->fd = open(j->path, O_RDWR | O_APPEND);
    if (j->fd < 0 && errno == ENOENT)
        return create_journal(j, key, err);
    if (j->fd < 0)
        return pd_err_set(err, PD_EIO, "--resume: cannot open %s: %s", j->path, strerror(errno));
    if (lock_fd(j->fd))
        return pd_err_set(err, PD_EINVAL, "--resume: %s is in use by a running sweep", j->path);
    char *buf = read_fd(j->fd, &len);
    if (!buf)
        return pd_err_set(err, PD_EIO, "--resume: cannot read %s", j->path);
    if (!(rc = check_header(j, buf, key, &body, err)) &&
        load_records(j, buf, len, body, ntasks, res, loaded))
        rc = pd_err_set(err, PD_EIO, "--resume: cannot repair the torn end of %s", j->path);
    free(buf);
    return rc;
}

int pd_spec_journal_open(pd_spec_journal *j, const char *out, const char *key, long ntasks,
                         int resume, pd_spec_result *res, long *loaded, pd_err *err)
{
    int rc;
    memset(j, 0, sizeof *j);
    j->fd = -1;
    j->last_sync = pd_wall_seconds();
    *loaded = 0;
    if (snprintf(j->path, sizeof j->path, "%s.partial", out) >= (int)sizeof j->path)
        return pd_err_set(err, PD_EINVAL, "-o %s: path too long", out);
    rc = resume ? resume_journal(j, key, ntasks, res, loaded, err) : create_journal(j, key, err);
    if (rc && j->fd >= 0) {
        close(j->fd);
        j->fd = -1;
    }
    return rc;
}

int pd_spec_journal_append(pd_spec_journal *j, long task, const pd_spec_result *r)
{
    char line[512];
    int n = format_record(line, sizeof line, task, r);
    if (j->fd < 0 || j->failed || n < 0 || write_all(j->fd, line, (size_t)n)) {
        j->failed = 1;
        return -1;
    }
    double now = pd_wall_seconds();
    if (now - j->last_sync >= 1.0) {
        j->last_sync = now;
        if (fdatasync(j->fd))
            j->failed = 1;
    }
    return j->failed ? -1 : 0;
}

void pd_spec_journal_close(pd_spec_journal *j, int remove)
{
    if (j->fd >= 0)
        close(j->fd);
    j->fd = -1;
    if (remove && j->path[0])
        unlink(j->path);
}
