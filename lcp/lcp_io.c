/* lcp_io.c — reading LCPs from text files (docs/lcp.md, "File formats").
 *
 * plain:   n, then M row by row (n*n numbers), then q (n numbers), nothing
 *          else; '#' starts a comment that runs to the end of the line.
 * siconos: n, 0 (dense storage), rows, cols, "rows cols" on one line, then
 *          M column by column, then q; any text after q is ignored.
 * The whole file is read, split into whitespace-separated tokens that remember
 * their line, and every error names the file and the line. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pd_lcp.h"

#define READ_NMAX 46340 /* n*n must fit an int */

typedef struct lcp_token {
    char *text; /* NUL-terminated, inside the file buffer */
    int line;   /* 1-based */
} lcp_token;

/* A file split into tokens. */
typedef struct lcp_text {
    const char *path;
    char *buf;       /* file contents + NUL */
    size_t len;
    lcp_token *tok;
    size_t ntok, cap;
    int last_line;   /* line of the end of the file */
} lcp_text;

/* Whole file into t->buf (NUL-terminated). */
static int slurp(lcp_text *t, pd_err *err)
{
    FILE *f = fopen(t->path, "rb");
    if (!f)
        return pd_err_set(err, PD_EIO, "%s: cannot open: %s", t->path, strerror(errno));
    size_t cap = 4096;
    int status = PD_OK;
    errno = 0;
    t->buf = malloc(cap);
    t->len = 0;
    while (t->buf) {
        t->len += fread(t->buf + t->len, 1, cap - 1 - t->len, f);
        if (t->len < cap - 1)
            break;
        char *grown = realloc(t->buf, 2 * cap);
        if (!grown)
            free(t->buf);
        t->buf = grown;
        cap *= 2;
    }
    if (!t->buf)
        status = pd_err_set(err, PD_ENOMEM, "%s: out of memory reading the file", t->path);
    else if (ferror(f))
        status = pd_err_set(err, PD_EIO, "%s: cannot read: %s", t->path, strerror(errno));
    else
        t->buf[t->len] = '\0';
    fclose(f);
    return status;
}

/* Whitespace inside a line (CR of CRLF included). */
static int is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* Append one token. */
static int push_token(lcp_text *t, char *text, int line)
{
    if (t->ntok == t->cap) {
        size_t cap = t->cap ? 2 * t->cap : 256;
        lcp_token *grown = realloc(t->tok, cap * sizeof *grown);
        if (!grown)
            return -1;
        t->tok = grown;
        t->cap = cap;
    }
    t->tok[t->ntok].text = text;
    t->tok[t->ntok].line = line;
    t->ntok++;
    return 0;
}

/* Split the buffer in place: tokens end at blanks, newlines and '#'. */
static int tokenize(lcp_text *t, pd_err *err)
{
    char *p = t->buf, *end = t->buf + t->len;
    int line = 1, in_comment = 0, final_newline = t->len > 0 && end[-1] == '\n';
    while (p < end) {
        char c = *p;
        if (c == '\n') {
            line++;
            in_comment = 0;
            *p++ = '\0';
        } else if (in_comment || is_blank(c)) {
            *p++ = '\0';
        } else if (c == '#') {
            in_comment = 1;
            *p++ = '\0';
        } else if (c == '\0') {
            return pd_err_set(err, PD_EPARSE, "%s: line %d: NUL byte in a text file", t->path,
                              line);
        } else {
            if (push_token(t, p, line) != 0)
                return pd_err_set(err, PD_ENOMEM, "%s: out of memory", t->path);
            while (p < end && *p != '\n' && *p != '#' && !is_blank(*p) && *p != '\0')
                p++;
        }
    }
    t->last_line = final_newline ? line - 1 : line; /* the line holding the last byte */
    return PD_OK;
}

/* Token k as a finite double. */
static int token_number(const lcp_text *t, size_t k, const char *what, double *x, pd_err *err)
{
    const lcp_token *tk = &t->tok[k];
    char *stop = NULL;
    errno = 0;
    double v = strtod(tk->text, &stop);
    if (stop == tk->text || *stop != '\0')
        return pd_err_set(err, PD_EPARSE, "%s: line %d: %s: '%.40s' is not a number", t->path,
                          tk->line, what, tk->text);
    if (isnan(v) || isinf(v) || (errno == ERANGE && fabs(v) > 1.0))
        return pd_err_set(err, PD_EPARSE, "%s: line %d: %s: '%.40s' is not a finite number",
                          t->path, tk->line, what, tk->text);
    *x = v;
    return PD_OK;
}

/* Token k as a decimal integer (no sign check). */
static int token_integer(const lcp_token *tk, long *v)
{
    char *stop = NULL;
    errno = 0;
    *v = strtol(tk->text, &stop, 10);
    return stop != tk->text && *stop == '\0' && errno == 0;
}

/* Token k as a size 1 <= n <= READ_NMAX. */
static int token_size(const lcp_text *t, size_t k, const char *what, int *n, pd_err *err)
{
    if (k >= t->ntok)
        return pd_err_set(err, PD_EPARSE, "%s: line %d: file ends before the %s", t->path,
                          t->last_line, what);
    long v = 0;
    const lcp_token *tk = &t->tok[k];
    if (!token_integer(tk, &v) || v <= 0)
        return pd_err_set(err, PD_EPARSE,
                          "%s: line %d: the %s must be a positive integer, got '%.40s'", t->path,
                          tk->line, what, tk->text);
    if (v > READ_NMAX)
        return pd_err_set(err, PD_EPARSE, "%s: line %d: the %s %ld is too large (at most %d)",
                          t->path, tk->line, what, v, READ_NMAX);
    *n = (int)v;
    return PD_OK;
}

/* Enough tokens from `first` on for n*n + n values? */
static int check_count(const lcp_text *t, size_t first, int n, pd_err *err)
{
    size_t need = (size_t)n * (size_t)n + (size_t)n;
    size_t have = t->ntok > first ? t->ntok - first : 0;
    if (have >= need)
        return PD_OK;
    return pd_err_set(err, PD_EPARSE,
                      "%s: line %d: too few values: the file ends after %zu of the %zu numbers "
                      "of M and q (n = %d)", t->path, t->last_line, have, need, n);
}

/* Allocate M and q. */
static int alloc_problem(const lcp_text *t, int n, double **M, double **q, pd_err *err)
{
    *M = malloc((size_t)n * (size_t)n * sizeof(double));
    *q = malloc((size_t)n * sizeof(double));
    if (*M && *q)
        return PD_OK;
    free(*M);
    free(*q);
    *M = *q = NULL;
    return pd_err_set(err, PD_ENOMEM, "%s: out of memory for n = %d", t->path, n);
}

/* n*n entries of M from token `first` on; row_major selects the layout. */
static int read_matrix(const lcp_text *t, size_t first, int n, int row_major, double *M,
                       pd_err *err)
{
    size_t nn = (size_t)n * (size_t)n;
    for (size_t k = 0; k < nn; k++) {
        size_t i = k / (size_t)n, j = k % (size_t)n;
        size_t at = row_major ? i + j * (size_t)n : k;
        int st = token_number(t, first + k, "matrix entry", &M[at], err);
        if (st != PD_OK)
            return st;
    }
    return PD_OK;
}

/* n entries of q from token `first` on. */
static int read_vector(const lcp_text *t, size_t first, int n, double *q, pd_err *err)
{
    for (int i = 0; i < n; i++) {
        int st = token_number(t, first + (size_t)i, "entry of q", &q[i], err);
        if (st != PD_OK)
            return st;
    }
    return PD_OK;
}

/* plain: n, M row by row, q, and nothing more. */
static int read_plain(const lcp_text *t, int *n, double **M, double **q, pd_err *err)
{
    if (t->ntok == 0)
        return pd_err_set(err, PD_EPARSE, "%s: line %d: empty file, expected the size n",
                          t->path, t->last_line);
    int st = token_size(t, 0, "size n", n, err);
    if (st == PD_OK)
        st = check_count(t, 1, *n, err);
    size_t used = 1 + (size_t)*n * (size_t)*n + (size_t)*n;
    if (st == PD_OK && t->ntok > used)
        st = pd_err_set(err, PD_EPARSE,
                        "%s: line %d: unexpected value '%.40s' after q (n = %d needs exactly "
                        "%zu numbers)", t->path, t->tok[used].line, t->tok[used].text, *n, used);
    if (st == PD_OK)
        st = alloc_problem(t, *n, M, q, err);
    if (st == PD_OK)
        st = read_matrix(t, 1, *n, 1, *M, err);
    if (st == PD_OK)
        st = read_vector(t, 1 + (size_t)*n * (size_t)*n, *n, *q, err);
    return st;
}

/* Siconos header: storage 0 and rows = cols = n, twice. */
static int check_siconos_header(const lcp_text *t, int n, pd_err *err)
{
    long v = 0;
    if (t->ntok < 6)
        return pd_err_set(err, PD_EPARSE, "%s: line %d: file ends inside the Siconos header "
                          "(n, storage, rows, cols, rows cols)", t->path, t->last_line);
    if (!token_integer(&t->tok[1], &v) || v != 0)
        return pd_err_set(err, PD_EPARSE, "%s: line %d: storage '%.40s' is not supported "
                          "(only 0 = dense)", t->path, t->tok[1].line, t->tok[1].text);
    for (size_t k = 2; k < 6; k++)
        if (!token_integer(&t->tok[k], &v) || v != n)
            return pd_err_set(err, PD_EPARSE, "%s: line %d: matrix dimension '%.40s' does not "
                              "match n = %d", t->path, t->tok[k].line, t->tok[k].text, n);
    return PD_OK;
}

/* siconos: header, M column by column, q; the rest is free text. */
static int read_siconos(const lcp_text *t, int *n, double **M, double **q, pd_err *err)
{
    if (t->ntok == 0)
        return pd_err_set(err, PD_EPARSE, "%s: line %d: empty file, expected the size n",
                          t->path, t->last_line);
    int st = token_size(t, 0, "size n", n, err);
    if (st == PD_OK)
        st = check_siconos_header(t, *n, err);
    if (st == PD_OK)
        st = check_count(t, 6, *n, err);
    if (st == PD_OK)
        st = alloc_problem(t, *n, M, q, err);
    if (st == PD_OK)
        st = read_matrix(t, 6, *n, 0, *M, err);
    if (st == PD_OK)
        st = read_vector(t, 6 + (size_t)*n * (size_t)*n, *n, *q, err);
    return st;
}

/* Siconos header layout: n, storage, rows, cols on lines of their own, then
 * "rows cols" on one line, all integers, repeated dims equal, and a token
 * count that a plain file of that n cannot have. */
static int looks_siconos(const lcp_text *t)
{
    long v[6];
    if (t->ntok < 6)
        return 0;
    for (int k = 0; k < 6; k++)
        if (!token_integer(&t->tok[k], &v[k]))
            return 0;
    const lcp_token *tk = t->tok;
    int lines_ok = tk[0].line < tk[1].line && tk[1].line < tk[2].line &&
                   tk[2].line < tk[3].line && tk[3].line < tk[4].line && tk[4].line == tk[5].line;
    if (!lines_ok || v[0] <= 0 || v[0] > READ_NMAX || v[2] != v[4] || v[3] != v[5])
        return 0;
    size_t plain_count = 1 + (size_t)v[0] * (size_t)v[0] + (size_t)v[0];
    return t->ntok != plain_count;
}

int pd_lcp_read(const char *path, pd_lcp_format format, int *n, double **M, double **q,
                pd_err *err)
{
    pd_err_clear(err);
    if (!path || !n || !M || !q)
        return pd_err_set(err, PD_EINVAL, "pd_lcp_read: NULL argument");
    if (format != PD_LCP_FORMAT_AUTO && format != PD_LCP_FORMAT_PLAIN &&
        format != PD_LCP_FORMAT_SICONOS)
        return pd_err_set(err, PD_EINVAL, "pd_lcp_read: unknown format %d", (int)format);
    *n = 0;
    *M = *q = NULL;
    lcp_text t = {.path = path};
    int st = slurp(&t, err);
    if (st == PD_OK)
        st = tokenize(&t, err);
    if (st == PD_OK) {
        int siconos = format == PD_LCP_FORMAT_SICONOS ||
                      (format == PD_LCP_FORMAT_AUTO && looks_siconos(&t));
        st = siconos ? read_siconos(&t, n, M, q, err) : read_plain(&t, n, M, q, err);
    }
    if (st != PD_OK) {
        free(*M);
        free(*q);
        *M = *q = NULL;
        *n = 0;
    }
    free(t.tok);
    free(t.buf);
    return st;
}
