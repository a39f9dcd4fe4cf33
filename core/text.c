/* text.c — input text files in bounded memory (pd_core.h): a NUL byte, a
 * file beyond its cap or a line beyond PD_TEXT_LINE_MAX is refused where it
 * is read, so /dev/zero or an endless stream costs at most the cap. */
#include "pd_core.h"
#include "pd_null.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define TEXT_CHUNK (64L << 10) /* first buffer of a whole-file read */

/* ---- messages --------------------------------------------------------------- */

/* "FILE:L", "FILE:L:C" or "FILE: line L" into buf. */
static const char *where(const char *path, pd_text_at at, long line, long col, char *buf,
                         size_t cap)
{
    if (at == PD_TEXT_AT_LINE_COL)
        snprintf(buf, cap, "%s:%ld:%ld", path, line, col);
    else if (at == PD_TEXT_AT_WORD)
        snprintf(buf, cap, "%s: line %ld", path, line);
    else
        snprintf(buf, cap, "%s:%ld", path, line);
    return buf;
}

/* A NUL byte at (line, col): binary data. */
static int fault_nul(const char *path, pd_text_at at, long line, long col, pd_err *err)
{
    char loc[300];
    return pd_err_set(err, PD_EPARSE, "%s: not a text file (a NUL byte)",
                      where(path, at, line, col, loc, sizeof loc));
}

/* More than max_bytes read, the last of them on line. */
static int fault_size(const char *path, pd_text_at at, long line, long col, long max_bytes,
                      pd_err *err)
{
    char loc[300];
    where(path, at, line, col, loc, sizeof loc);
    if (max_bytes % (1L << 20) == 0)
        return pd_err_set(err, PD_EPARSE, "%s: the file is larger than %ld MiB, the most read", loc,
                          max_bytes >> 20);
    return pd_err_set(err, PD_EPARSE, "%s: the file is larger than %ld bytes, the most read", loc,
                      max_bytes);
}

/* A read error (errno) on line. */
static int fault_read(const char *path, pd_text_at at, long line, pd_err *err)
{
    char loc[300];
    int e = errno ? errno : EIO;
    return pd_err_set(err, e == ENOMEM ? PD_ENOMEM : PD_EIO, "%s: cannot read: %s",
                      where(path, at, line, 1, loc, sizeof loc), strerror(e));
}

/* ---- line by line --------------------------------------------------------------- */

int pd_text_open(pd_text *t, const char *path, long max_bytes, pd_text_at at, pd_err *err)
{
    if (!t)
        return PD_NULL_ARG(err, "t");
    *t = (pd_text){.path = path, .max_bytes = max_bytes, .at = at, .err = err};
    if (!path || max_bytes < 1)
        return pd_err_set(err, PD_EINVAL, "pd_text_open: no file or a cap of %ld bytes", max_bytes);
    /* without blocking: opening a FIFO for reading waits for a writer */
    errno = 0;
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return pd_err_set(err, PD_EIO, "%s: cannot open: %s", path, strerror(errno ? errno : EIO));
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        const char *what = S_ISFIFO(st.st_mode)   ? "a FIFO"
                           : S_ISDIR(st.st_mode)  ? "a directory"
                           : S_ISCHR(st.st_mode)  ? "a device"
                           : S_ISSOCK(st.st_mode) ? "a socket"
                                                  : "not a file";
        close(fd);
        return pd_err_set(err, PD_EINVAL, "%s: not a regular file (%s)", path, what);
    }
    int flags = fcntl(fd, F_GETFL);
    if (flags < 0 || fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0 || !(t->f = fdopen(fd, "rb"))) {
        int e = errno ? errno : EIO;
        close(fd);
        return pd_err_set(err, PD_EIO, "%s: cannot open: %s", path, strerror(e));
    }
    return PD_OK;
}

/* Room for need bytes in the line buffer (need <= PD_TEXT_LINE_MAX + 2). */
static int line_grow(pd_text *t, size_t need)
{
    size_t cap = t->cap ? t->cap : 256;
    while (cap < need)
        cap *= 2;
    if (cap > (size_t)PD_TEXT_LINE_MAX + 2)
        cap = (size_t)PD_TEXT_LINE_MAX + 2;
    char *grown = realloc(t->line, cap);
    if (!grown)
        return pd_err_set(t->err, PD_ENOMEM, "%s: out of memory for a line of %zu bytes", t->path,
                          need);
    t->line = grown;
    t->cap = cap;
    return PD_OK;
}

int pd_text_line(pd_text *t)
{
    char loc[300];
    size_t n = 0;
    int c;
    if (!t || !t->f)
        return PD_EINVAL;
    long line = t->lineno + 1;
    errno = 0;
    while ((c = getc_unlocked(t->f)) != EOF) {
        if (c == '\0')
            return fault_nul(t->path, t->at, line, (long)n + 1, t->err);
        if (t->bytes >= t->max_bytes)
            return fault_size(t->path, t->at, line, (long)n + 1, t->max_bytes, t->err);
        if (n >= (size_t)PD_TEXT_LINE_MAX)
            return pd_err_set(t->err, PD_EPARSE,
                              "%s: a line longer than %ld MiB: not a text "
                              "file",
                              where(t->path, t->at, line, 1, loc, sizeof loc),
                              PD_TEXT_LINE_MAX >> 20);
        int st = n + 2 > t->cap ? line_grow(t, n + 2) : PD_OK;
        if (st != PD_OK)
            return st;
        t->line[n++] = (char)c;
        t->bytes++;
        if (c == '\n')
            break;
    }
    if (ferror(t->f))
        return fault_read(t->path, t->at, line, t->err);
    t->len = n;
    if (n == 0)
        return 0;
    t->line[n] = '\0';
    t->lineno = line;
    return 1;
}

int pd_text_rewind(pd_text *t)
{
    if (!t || !t->f)
        return PD_EINVAL;
    errno = 0;
    if (fseek(t->f, 0L, SEEK_SET) != 0)
        return pd_err_set(t->err, PD_EIO, "%s: cannot go back to its start to read it again: %s",
                          t->path, strerror(errno ? errno : EIO));
    clearerr(t->f);
    t->lineno = 0;
    t->bytes = 0;
    t->len = 0;
    return PD_OK;
}

void pd_text_close(pd_text *t)
{
    if (!t)
        return;
    if (t->f)
        fclose(t->f);
    free(t->line);
    t->f = NULL;
    t->line = NULL;
    t->len = t->cap = 0;
}

/* ---- the whole file ----------------------------------------------------------------- */

/* Line and column (1-based) of offset k in buf. */
static void offset_place(const char *buf, size_t k, long *line, long *col)
{
    size_t start = 0;
    *line = 1;
    for (size_t i = 0; i < k; i++)
        if (buf[i] == '\n') {
            (*line)++;
            start = i + 1;
        }
    *col = (long)(k - start) + 1;
}

/* Room in *buf (of *cap bytes) beyond n, the buffer at most max_bytes + 2. */
static int all_grow(char **buf, size_t *cap, size_t n, long max_bytes)
{
    if (n + 1 < *cap)
        return PD_OK;
    size_t ncap = *cap ? 2 * *cap : (size_t)TEXT_CHUNK;
    if (ncap > (size_t)max_bytes + 2)
        ncap = (size_t)max_bytes + 2;
    char *grown = realloc(*buf, ncap);
    if (!grown)
        return PD_ENOMEM;
    *buf = grown;
    *cap = ncap;
    return PD_OK;
}

int pd_text_read_all(const char *path, long max_bytes, pd_text_at at, char **text, size_t *len,
                     pd_err *err)
{
    pd_text t;
    char *buf = NULL;
    size_t n = 0, cap = 0;
    long line, col;
    if (!text || !len)
        return PD_NULL_ARG(err, !text ? "text" : "len");
    *text = NULL;
    *len = 0;
    int st = pd_text_open(&t, path, max_bytes, at, err);
    while (st == PD_OK) {
        if (all_grow(&buf, &cap, n, max_bytes) != PD_OK) {
            st = pd_err_set(err, PD_ENOMEM, "%s: out of memory reading %zu bytes", path, n);
            break;
        }
        errno = 0;
        size_t got = fread(buf + n, 1, cap - 1 - n, t.f);
        const char *nul = memchr(buf + n, '\0', got);
        if (nul) {
            offset_place(buf, (size_t)(nul - buf), &line, &col);
            st = fault_nul(path, at, line, col, err);
        } else if (n + got > (size_t)max_bytes) {
            offset_place(buf, (size_t)max_bytes, &line, &col);
            st = fault_size(path, at, line, col, max_bytes, err);
        } else if (got == 0 && ferror(t.f)) {
            offset_place(buf, n, &line, &col);
            st = fault_read(path, at, line, err);
        } else if (got == 0) {
            break; /* the end of the file */
        }
        n += got;
    }
    pd_text_close(&t);
    if (st != PD_OK) {
        free(buf);
        return st;
    }
    buf[n] = '\0';
    *text = buf;
    *len = n;
    return PD_OK;
}
