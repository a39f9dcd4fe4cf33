/* journal.c — an append-only journal of finished work (pd_journal.h): a
 * magic line, the run's key, then one checksummed line per finished item.
 *
 * Each line is one write(2) on an O_APPEND descriptor; fdatasync runs at
 * most once a second (an OS crash loses at most that much work; a killed
 * process loses nothing written).  A POSIX record lock keeps two runs from
 * sharing one journal.  Reading back drops lines whose checksum fails and
 * cuts a torn last line (no newline) off the file. */
#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pd_journal.h"

/* FNV-1a hash of n bytes (the line checksum). */
static uint32_t fnv1a(const char *p, size_t n)
{
    uint32_t h = 2166136261u;
    for (size_t i = 0; i < n; i++) {
        h ^= (unsigned char)p[i];
        h *= 16777619u;
    }
    return h;
}

/* The checksummed line of body into line (cap bytes): its length, or -1
 * when it does not fit. */
static int journal_line(const char *body, size_t len, char *line, size_t cap)
{
    if (len + 12 > cap)
        return -1;
    memcpy(line, body, len);
    int m = snprintf(line + len, cap - len, " #%08lx\n", (unsigned long)fnv1a(body, len));
    return m < 0 || len + (size_t)m >= cap ? -1 : (int)(len + (size_t)m);
}

/* A line (without its newline) checked: its body's length, or -1 when the
 * checksum does not match. */
static long journal_check(const char *line, size_t len)
{
    const char *hash = NULL;
    char buf[16], *end;
    for (size_t i = len; i-- > 0;)
        if (line[i] == '#') {
            hash = line + i;
            break;
        }
    if (!hash || hash == line || hash[-1] != ' ' || line + len - hash - 1 > 8 ||
        line + len - hash - 1 < 1)
        return -1;
    memcpy(buf, hash + 1, (size_t)(line + len - hash - 1));
    buf[line + len - hash - 1] = '\0';
    size_t body = (size_t)(hash - 1 - line);
    if (strtoul(buf, &end, 16) != fnv1a(line, body) || *end)
        return -1;
    return (long)body;
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
static int create_journal(pd_journal *j, const pd_journal_kind *kd, const char *key, pd_err *err)
{
    j->fd = open(j->path, O_WRONLY | O_CREAT | O_EXCL | O_APPEND, 0644);
    if (j->fd < 0 && errno == EEXIST)
        return pd_err_set(err, PD_EINVAL,
                          "%s: %s exists: an interrupted %s; add --resume to continue it, or "
                          "delete it",
                          kd->flag, j->path, kd->run);
    if (j->fd < 0)
        return pd_err_set(err, PD_EIO, "%s: cannot create %s: %s", kd->flag, j->path,
                          strerror(errno));
    /* the header in one write: a killed process leaves all of it or none */
    size_t lm = strlen(kd->magic), lk = strlen(key);
    char *head = malloc(lm + lk + 6);
    if (head) {
        memcpy(head, kd->magic, lm);
        memcpy(head + lm, "key ", 4);
        memcpy(head + lm + 4, key, lk);
        head[lm + 4 + lk] = '\n';
    }
    int bad = !head || lock_fd(j->fd) || write_all(j->fd, head, lm + lk + 5) || fdatasync(j->fd);
    free(head);
    if (bad) {
        int e = errno ? errno : EIO;
        close(j->fd);
        j->fd = -1;
        unlink(j->path);
        return pd_err_set(err, PD_EIO, "%s: cannot write %s: %s", kd->flag, j->path, strerror(e));
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
            size_t k = strcspn(b, "= "); /* a name as its flag, a flag or <what> as it is */
            int bare = (b[0] >= 'a' && b[0] <= 'z') || (b[0] >= 'A' && b[0] <= 'Z');
            snprintf(name, cap, "%s%.*s", bare ? "--" : "", (int)(k < 60 ? k : 60), b);
            return;
        }
        a += la + (a[la] == ' ');
        b += lb + (b[lb] == ' ');
    }
}

/* Check the header lines against key: 0, or PD_EINVAL naming what differs. */
static int check_header(const pd_journal *j, const pd_journal_kind *kd, const char *buf,
                        const char *key, size_t *body, pd_err *err)
{
    size_t lm = strlen(kd->magic), lk = strlen(key);
    char what[80];
    if (strncmp(buf, kd->magic, lm) || strncmp(buf + lm, "key ", 4))
        return pd_err_set(err, PD_EINVAL, "--resume: %s is not a pound %s journal", j->path,
                          kd->what);
    const char *k = buf + lm + 4, *nl = strchr(k, '\n');
    if (!nl || (size_t)(nl - k) != lk || memcmp(k, key, lk)) {
        char *old = nl ? strndup(k, (size_t)(nl - k)) : NULL;
        first_difference(old ? old : "", key, what, sizeof what);
        free(old);
        return pd_err_set(err, PD_EINVAL,
                          "--resume: %s belongs to a different %s (%s differs); repeat that "
                          "%s's flags or delete it",
                          j->path, kd->run, what, kd->run);
    }
    *body = (size_t)(nl + 1 - buf);
    return PD_OK;
}

/* The lines after the header through read; a torn tail (no newline) is cut
 * off the file. */
static int load_lines(pd_journal *j, const char *buf, size_t len, size_t pos,
                      pd_journal_reader read, void *ctx)
{
    while (pos < len) {
        const char *nl = memchr(buf + pos, '\n', len - pos);
        if (!nl)
            return ftruncate(j->fd, (off_t)pos);
        long body = journal_check(buf + pos, (size_t)(nl - buf - pos));
        if (body >= 0)
            read(buf + pos, (size_t)body, ctx); /* a malformed line is skipped */
        pos = (size_t)(nl + 1 - buf);
    }
    return 0;
}

/* Reopen an existing journal (or start one): its lines through read. */
static int resume_journal(pd_journal *j, const pd_journal_kind *kd, const char *key,
                          pd_journal_reader read, void *ctx, pd_err *err)
{
    size_t len = 0, body = 0;
    int rc;
    j->fd = open(j->path, O_RDWR | O_APPEND);
    if (j->fd < 0 && errno == ENOENT)
        return create_journal(j, kd, key, err);
    if (j->fd < 0)
        return pd_err_set(err, PD_EIO, "--resume: cannot open %s: %s", j->path, strerror(errno));
    if (lock_fd(j->fd))
        return pd_err_set(err, PD_EINVAL, "--resume: %s is in use by a running %s", j->path,
                          kd->run);
    char *buf = read_fd(j->fd, &len);
    if (!buf)
        return pd_err_set(err, PD_EIO, "--resume: cannot read %s", j->path);
    if (!(rc = check_header(j, kd, buf, key, &body, err)) &&
        load_lines(j, buf, len, body, read, ctx))
        rc = pd_err_set(err, PD_EIO, "--resume: cannot repair the torn end of %s", j->path);
    free(buf);
    return rc;
}

int pd_journal_open(pd_journal *j, const pd_journal_kind *kind, const char *path, const char *key,
                    int resume, pd_journal_reader read, void *ctx, pd_err *err)
{
    int rc;
    memset(j, 0, sizeof *j);
    j->fd = -1;
    j->last_sync = pd_wall_seconds();
    if (snprintf(j->path, sizeof j->path, "%s", path) >= (int)sizeof j->path)
        return pd_err_set(err, PD_EINVAL, "%s %s: path too long", kind->flag, path);
    rc = resume ? resume_journal(j, kind, key, read, ctx, err) : create_journal(j, kind, key, err);
    if (rc && j->fd >= 0) {
        close(j->fd);
        j->fd = -1;
    }
    return rc;
}

int pd_journal_append(pd_journal *j, const char *body, size_t len)
{
    size_t cap = len + 16; /* the body, " #xxxxxxxx\n" and its NUL */
    char small[1024], *line = cap <= sizeof small ? small : malloc(cap);
    int n = line ? journal_line(body, len, line, cap) : -1;
    if (j->fd < 0 || j->failed || n < 0 || write_all(j->fd, line, (size_t)n))
        j->failed = 1;
    if (line != small)
        free(line);
    if (j->failed)
        return -1;
    double now = pd_wall_seconds();
    if (now - j->last_sync >= 1.0) {
        j->last_sync = now;
        if (fdatasync(j->fd))
            j->failed = 1;
    }
    return j->failed ? -1 : 0;
}

void pd_journal_close(pd_journal *j, int remove)
{
    if (j->fd >= 0)
        close(j->fd);
    j->fd = -1;
    if (remove && j->path[0])
        unlink(j->path);
}
