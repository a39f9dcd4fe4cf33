/* lcp_io.c — reading LCPs from text files (docs/lcp.md, "File formats").
 *
 * plain:   n, then M row by row (n*n numbers), then q (n numbers), nothing
 *          else; '#' starts a comment that runs to the end of the line.
 * siconos: n, 0 (dense storage), rows, cols, "rows cols" on one line, then
 *          M column by column, then q; any text after q is ignored.
 * The whole file is read (bounded: pd_text_read_all), then walked token by token
 * (whitespace-separated, each with its line) with no token array, so memory
 * is the file and the problem; every error names the file and the line. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pd_lcp.h"
#include "pd_core.h"

#define READ_NMAX 46340 /* n*n must fit an int */

/* Largest LCP file read: 512 MiB, a dense n = 4096 problem at 30
 * characters an entry (Lemke takes n <= 2048; larger problems come as
 * HDF5 dumps).  The cap bounds what an endless input (/dev/zero, a
 * stream) costs before it is refused. */
#define LCP_FILE_MAX (512L << 20)

/* A token: text[0 .. len) inside the file buffer, on a 1-based line. */
typedef struct lcp_token {
    const char *text;
    size_t len;
    int line;
} lcp_token;

/* A place in the file: the next byte, its line, inside a comment or not. */
typedef struct lcp_cursor {
    const char *p;
    int line, in_comment;
} lcp_cursor;

/* The file's text. */
typedef struct lcp_text {
    const char *path;
    char *buf; /* file contents + NUL (no NUL inside) */
    size_t len;
    int last_line; /* line of the end of the file */
} lcp_text;

/* Whole file into t->buf (NUL-terminated, no NUL inside: pd_text_read_all). */
static int slurp(lcp_text *t, pd_err *err)
{
    return pd_text_read_all(t->path, LCP_FILE_MAX, PD_TEXT_AT_WORD, &t->buf, &t->len, err);
}

/* Whitespace inside a line (CR of CRLF included). */
static int is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* The start of the file, and the line holding its last byte. */
static lcp_cursor text_start(lcp_text *t)
{
    int lines = 1;
    for (size_t k = 0; k < t->len; k++)
        lines += t->buf[k] == '\n';
    /* a final newline opens no line of its own */
    t->last_line = t->len > 0 && t->buf[t->len - 1] == '\n' ? lines - 1 : lines;
    return (lcp_cursor){.p = t->buf, .line = 1};
}

/* The next token at c: 1, or 0 at the end of the file.  Tokens end at
 * blanks, newlines and '#'. */
static int next_token(const lcp_text *t, lcp_cursor *c, lcp_token *tk)
{
    const char *end = t->buf + t->len;
    for (; c->p < end; c->p++) {
        char ch = *c->p;
        if (ch == '\n') { /* a comment ends with its line */
            c->line++;
            c->in_comment = 0;
        } else if (ch == '#') {
            c->in_comment = 1;
        } else if (!c->in_comment && !is_blank(ch)) {
            /* a token: up to a blank, a newline or a # */
            const char *s = c->p;
            while (c->p < end && *c->p != '\n' && *c->p != '#' && !is_blank(*c->p))
                c->p++;
            *tk = (lcp_token){.text = s, .len = (size_t)(c->p - s), .line = c->line};
            return 1;
        }
    }
    return 0;
}

/* Up to `limit` tokens from c on: how many there are (c is a copy). */
static size_t count_tokens(const lcp_text *t, lcp_cursor c, size_t limit)
{
    lcp_token tk;
    size_t k = 0;
    while (k < limit && next_token(t, &c, &tk))
        k++;
    return k;
}

/* Length of a token as printed in messages (at most 40 characters). */
static int shown(const lcp_token *tk)
{
    return tk->len > 40 ? 40 : (int)tk->len;
}

/* Token as a decimal integer (no sign check). */
static int token_integer(const lcp_token *tk, long *v)
{
    char *stop = NULL;
    errno = 0; /* strtol reports overflow through errno */
    *v = strtol(tk->text, &stop, 10);
    /* all of the token, in range */
    return stop != tk->text && stop == tk->text + tk->len && errno == 0;
}

/* The next token as a finite double (the count was checked: it exists). */
static int token_number(const lcp_text *t, lcp_cursor *c, const char *what, double *x, pd_err *err)
{
    /* the end of the file if no token were left (the count was checked) */
    lcp_token tk = {.text = t->buf + t->len, .line = t->last_line};
    next_token(t, c, &tk);
    char *stop = NULL;
    errno = 0;
    double v = strtod(tk.text, &stop);
    /* the whole token must be the number */
    if (stop == tk.text || stop != tk.text + tk.len)
        return pd_err_set(err, PD_EPARSE, "%s: line %d: %s: '%.*s' is not a number", t->path,
                          tk.line, what, shown(&tk), tk.text);
    /* inf, nan and overflow refused; an underflow (ERANGE
     * with |v| <= 1) is kept as strtod rounds it */
    if (isnan(v) || isinf(v) || (errno == ERANGE && fabs(v) > 1.0))
        return pd_err_set(err, PD_EPARSE, "%s: line %d: %s: '%.*s' is not a finite number", t->path,
                          tk.line, what, shown(&tk), tk.text);
    *x = v;
    return PD_OK;
}

/* The next token as a size 1 <= n <= READ_NMAX. */
static int token_size(const lcp_text *t, lcp_cursor *c, const char *what, int *n, pd_err *err)
{
    lcp_token tk;
    if (!next_token(t, c, &tk))
        return pd_err_set(err, PD_EPARSE, "%s: line %d: file ends before the %s", t->path,
                          t->last_line, what);
    long v = 0;
    if (!token_integer(&tk, &v) || v <= 0)
        return pd_err_set(err, PD_EPARSE,
                          "%s: line %d: the %s must be a positive integer, got '%.*s'", t->path,
                          tk.line, what, shown(&tk), tk.text);
    /* n n must fit an int */
    if (v > READ_NMAX)
        return pd_err_set(err, PD_EPARSE, "%s: line %d: the %s %ld is too large (at most %d)",
                          t->path, tk.line, what, v, READ_NMAX);
    *n = (int)v;
    return PD_OK;
}

/* Enough tokens from c on for n*n + n values? */
static int check_count(const lcp_text *t, lcp_cursor c, int n, pd_err *err)
{
    size_t need = (size_t)n * (size_t)n + (size_t)n;
    size_t have = count_tokens(t, c, need); /* counted up to need only */
    if (have >= need)
        return PD_OK;
    return pd_err_set(err, PD_EPARSE,
                      "%s: line %d: too few values: the file ends after %zu of the %zu numbers "
                      "of M and q (n = %d)",
                      t->path, t->last_line, have, need, n);
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
    *M = *q = NULL; /* the caller frees nothing */
    return pd_err_set(err, PD_ENOMEM, "%s: out of memory for n = %d", t->path, n);
}

/* The band of M seen while it is read: max |i - j| over the nonzero M_ij
 * (-1: none), and how many there are. */
typedef struct lcp_band {
    int band;
    long nnz;
} lcp_band;

/* n*n entries of M from c on; row_major selects the layout.  The band is
 * noted entry by entry as it is read: no pass of its own. */
static int read_matrix(const lcp_text *t, lcp_cursor *c, int n, int row_major, double *M,
                       lcp_band *band, pd_err *err)
{
    size_t nn = (size_t)n * (size_t)n;
    band->band = -1;
    band->nnz = 0;
    for (size_t k = 0; k < nn; k++) {
        /* row by row, token k is M_ij, i = k / n, j = k % n, stored column-major at
         * i + j n; column by column it is stored at k (|i - j| the same either way) */
        size_t i = k / (size_t)n, j = k % (size_t)n;
        size_t at = row_major ? i + j * (size_t)n : k;
        int st = token_number(t, c, "matrix entry", &M[at], err);
        if (st != PD_OK)
            return st;
        /* band = max |i - j| over the nonzero entries */
        if (M[at] != 0.0) {
            int d = (int)(i > j ? i - j : j - i);
            band->band = d > band->band ? d : band->band;
            band->nnz++;
        }
    }
    return PD_OK;
}

/* n entries of q from c on. */
static int read_vector(const lcp_text *t, lcp_cursor *c, int n, double *q, pd_err *err)
{
    for (int i = 0; i < n; i++) {
        int st = token_number(t, c, "entry of q", &q[i], err);
        if (st != PD_OK)
            return st;
    }
    return PD_OK;
}

/* Nothing after the n*n + n values from c on (c is a copy; the count was
 * checked). */
static int check_nothing_after(const lcp_text *t, lcp_cursor c, int n, pd_err *err)
{
    size_t need = (size_t)n * (size_t)n + (size_t)n;
    lcp_token tk;
    /* skip the n n + n values, then nothing may follow */
    for (size_t k = 0; k < need; k++)
        next_token(t, &c, &tk);
    if (!next_token(t, &c, &tk))
        return PD_OK;
    return pd_err_set(err, PD_EPARSE,
                      "%s: line %d: unexpected value '%.*s' after q (n = %d needs exactly "
                      "%zu numbers)",
                      t->path, tk.line, shown(&tk), tk.text, n, need + 1);
}

/* plain: n, M row by row, q, and nothing more. */
static int read_plain(const lcp_text *t, lcp_cursor c, int *n, double **M, double **q,
                      lcp_band *band, pd_err *err)
{
    if (count_tokens(t, c, 1) == 0)
        return pd_err_set(err, PD_EPARSE, "%s: line %d: empty file, expected the size n", t->path,
                          t->last_line);
    /* every check before the allocation: a malformed file costs no n^2 memory */
    int st = token_size(t, &c, "size n", n, err);
    if (st == PD_OK)
        st = check_count(t, c, *n, err);
    if (st == PD_OK)
        st = check_nothing_after(t, c, *n, err);
    if (st == PD_OK)
        st = alloc_problem(t, *n, M, q, err);
    if (st == PD_OK)
        st = read_matrix(t, &c, *n, 1, *M, band, err);
    if (st == PD_OK)
        st = read_vector(t, &c, *n, *q, err);
    return st;
}

/* Siconos header after n: storage 0 and rows = cols = n, twice. */
static int check_siconos_header(const lcp_text *t, lcp_cursor *c, int n, pd_err *err)
{
    lcp_token tk[5];
    long v = 0;
    for (int k = 0; k < 5; k++)
        if (!next_token(t, c, &tk[k]))
            return pd_err_set(err, PD_EPARSE,
                              "%s: line %d: file ends inside the Siconos header "
                              "(n, storage, rows, cols, rows cols)",
                              t->path, t->last_line);
    /* storage 0: dense */
    if (!token_integer(&tk[0], &v) || v != 0)
        return pd_err_set(err, PD_EPARSE,
                          "%s: line %d: storage '%.*s' is not supported "
                          "(only 0 = dense)",
                          t->path, tk[0].line, shown(&tk[0]), tk[0].text);
    /* rows, cols, and "rows cols": all n */
    for (int k = 1; k < 5; k++)
        if (!token_integer(&tk[k], &v) || v != n)
            return pd_err_set(err, PD_EPARSE,
                              "%s: line %d: matrix dimension '%.*s' does not "
                              "match n = %d",
                              t->path, tk[k].line, shown(&tk[k]), tk[k].text, n);
    return PD_OK;
}

/* siconos: header, M column by column, q; the rest is free text. */
static int read_siconos(const lcp_text *t, lcp_cursor c, int *n, double **M, double **q,
                        lcp_band *band, pd_err *err)
{
    if (count_tokens(t, c, 1) == 0)
        return pd_err_set(err, PD_EPARSE, "%s: line %d: empty file, expected the size n", t->path,
                          t->last_line);
    /* header and count checked before the allocation; free text may follow q */
    int st = token_size(t, &c, "size n", n, err);
    if (st == PD_OK)
        st = check_siconos_header(t, &c, *n, err);
    if (st == PD_OK)
        st = check_count(t, c, *n, err);
    if (st == PD_OK)
        st = alloc_problem(t, *n, M, q, err);
    if (st == PD_OK)
        st = read_matrix(t, &c, *n, 0, *M, band, err);
    if (st == PD_OK)
        st = read_vector(t, &c, *n, *q, err);
    return st;
}

/* Siconos header layout: n, storage, rows, cols on lines of their own, then
 * "rows cols" on one line, all integers, repeated dims equal, and a token
 * count that a plain file of that n cannot have (c is a copy). */
static int looks_siconos(const lcp_text *t, lcp_cursor c)
{
    lcp_token tk[6];
    long v[6];
    /* six integers: n, storage, rows, cols, rows cols */
    for (int k = 0; k < 6; k++)
        if (!next_token(t, &c, &tk[k]) || !token_integer(&tk[k], &v[k]))
            return 0;
    /* the first four on lines of their own, the last two on one line */
    int lines_ok = tk[0].line < tk[1].line && tk[1].line < tk[2].line && tk[2].line < tk[3].line &&
                   tk[3].line < tk[4].line && tk[4].line == tk[5].line;
    if (!lines_ok || v[0] <= 0 || v[0] > READ_NMAX || v[2] != v[4] || v[3] != v[5])
        return 0;
    size_t plain_count = 1 + (size_t)v[0] * (size_t)v[0] + (size_t)v[0];
    /* plain_count is 3 or >= 7; counting one past it decides */
    return plain_count < 6 || 6 + count_tokens(t, c, plain_count - 5) != plain_count;
}

int pd_lcp_read(const char *path, pd_lcp_format format, int *n, double **M, double **q, pd_err *err)
{
    return pd_lcp_read_band(path, format, n, M, q, NULL, NULL, err);
}

int pd_lcp_read_band(const char *path, pd_lcp_format format, int *n, double **M, double **q,
                     int *band, long *nnz, pd_err *err)
{
    lcp_band b = {.band = -1, .nnz = 0};
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
    if (st == PD_OK) {
        lcp_cursor c = text_start(&t);
        /* auto: the Siconos header, or else plain */
        int siconos = format == PD_LCP_FORMAT_SICONOS ||
                      (format == PD_LCP_FORMAT_AUTO && looks_siconos(&t, c));
        st = siconos ? read_siconos(&t, c, n, M, q, &b, err) : read_plain(&t, c, n, M, q, &b, err);
    }
    /* a failure returns nothing: no half-read problem */
    if (st != PD_OK) {
        free(*M);
        free(*q);
        *M = *q = NULL;
        *n = 0;
    }
    free(t.buf);
    if (band)
        *band = st == PD_OK ? b.band : -1; /* -1: no band */
    if (nnz)
        *nnz = st == PD_OK ? b.nnz : 0;
    return st;
}

long pd_lcp_band_csc(int n, const double *M, int band, long cap, int *colptr, int *rowind,
                     double *values)
{
    if (n < 1 || !M || band < -1 || !colptr || !rowind || !values)
        return PD_EINVAL;
    long k = 0;
    for (int j = 0; j < n; j++) {
        const double *c = M + (size_t)j * (size_t)n;
        /* rows j - band .. j + band of column j, inside the matrix */
        int lo = j - band > 0 ? j - band : 0, hi = j + band < n - 1 ? j + band : n - 1;
        colptr[j] = (int)k;
        for (int i = lo; i <= hi; i++)
            if (c[i] != 0.0) { /* true for a NaN */
                if (k == cap)  /* more entries than the copy holds */
                    return PD_EINVAL;
                rowind[k] = i;
                values[k++] = c[i];
            }
    }
    colptr[n] = (int)k; /* the entries copied */
    return k;
}
