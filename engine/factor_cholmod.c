/* factor_cholmod.c — the sparse storage kind: What = M + h theta C +
 * h^2 theta^2 K symmetric positive definite, ordered (AMD) and factored
 * once by CHOLMOD as P What P^T = L L^T (simplicial), then kept as plain
 * compressed columns so that a step calls no library:
 *   solve     x = P^T L^-T L^-1 P x                         O(nnz L)
 *   Z         = What^-1 W, column by column by sparse triangular solves
 *               over the reach of W_a only (CXSparse's cs_spsolve)
 *   D         = W^T Z, sparse m x m: contacts a, b are coupled only when
 *               W_a and W_b reach a common coupled block of What.
 * For a row of structures that touch only through contacts, Z holds one
 * structure's dofs per contact and D is (block) tridiagonal: nothing of
 * size n^2 or m^2 is ever formed. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cholmod.h>
#include <cs.h>

#include "pd_alloc.h"
#include "pd_factor.h"

#define CHOL_SYMMETRY_TOL 1e-12 /* |What_ij - What_ji| allowed, relative to max|What| */

typedef struct chol_data {
    int n, m;
    int *Lp, *Li; /* L, n x n lower, diagonal first in each column */
    double *Lx;
    int *Up, *Ui; /* U = L^T, diagonal last in each column */
    double *Ux;
    int *perm;    /* row k of P What P^T is row perm[k] of What */
    int *pinv;    /* pinv[perm[k]] = k */
    int *Zp, *Zi; /* Z = What^-1 W, n x m */
    double *Zx;
    int *Dp, *Di; /* D = W^T Z, m x m */
    double *Dx;
    int *pos;     /* m: place of a contact in the current index set, or -1 */
    double *work; /* n: the permuted right-hand side */
} chol_data;

static void chol_release(pd_factor *f)
{
    chol_data *d = f->data;
    if (!d)
        return;
    free(d->Lp);
    free(d->Li);
    free(d->Lx);
    free(d->Up);
    free(d->Ui);
    free(d->Ux);
    free(d->perm);
    free(d->pinv);
    free(d->Zp);
    free(d->Zi);
    free(d->Zx);
    free(d->Dp);
    free(d->Di);
    free(d->Dx);
    free(d->pos);
    free(d->work);
    free(d);
    f->data = NULL;
}

/* Triplets of s A (every stored entry of the view) appended at *nt. */
static void add_triplets(const pd_matrix *A, double s, int *Ti, int *Tj, double *Tx, long *nt)
{
    if (A->kind == PD_MATRIX_ZERO || s == 0.0) /* nothing to add */
        return;
    for (int j = 0; j < A->cols; j++) {
        /* compressed columns: every stored entry; dense: the nonzeros */
        if (A->kind == PD_MATRIX_CSC)
            for (int k = A->colptr[j]; k < A->colptr[j + 1]; k++) {
                Ti[*nt] = A->rowind[k];
                Tj[*nt] = j;
                Tx[(*nt)++] = s * A->values[k];
            }
        else
            for (int i = 0; i < A->rows; i++)
                if (A->values[i + (size_t)j * A->rows] != 0.0) {
                    Ti[*nt] = i;
                    Tj[*nt] = j;
                    Tx[(*nt)++] = s * A->values[i + (size_t)j * A->rows];
                }
    }
}

/* What = M + ht C + ht^2 K (or W alone: ht < 0) as an owned sparse matrix. */
static int assemble(const pd_model *md, double ht, int which_w, pd_sparse *out, pd_err *err)
{
    /* room for every stored entry of W, or of M, C and K together */
    long cap = which_w ? pd_matrix_nnz(&md->W)
                       : pd_matrix_nnz(&md->M) + pd_matrix_nnz(&md->C) + pd_matrix_nnz(&md->K);
    int *Ti = malloc((size_t)(cap + 1) * sizeof(int)),
        *Tj = malloc((size_t)(cap + 1) * sizeof(int));
    double *Tx = malloc((size_t)(cap + 1) * sizeof(double));
    long nt = 0;
    int rc;
    if (!Ti || !Tj || !Tx) {
        rc = pd_err_set(err, PD_ENOMEM, "factor: out of memory for %ld entries", cap);
    } else {
        if (which_w)
            add_triplets(&md->W, 1.0, Ti, Tj, Tx, &nt);
        else {
            add_triplets(&md->M, 1.0, Ti, Tj, Tx, &nt);
            add_triplets(&md->C, ht, Ti, Tj, Tx, &nt);
            add_triplets(&md->K, ht * ht, Ti, Tj, Tx, &nt);
        }
        /* the triplets into compressed columns */
        rc = pd_sparse_from_triplets(out, md->n, which_w ? md->m : md->n, nt, Ti, Tj, Tx, err);
    }
    free(Ti);
    free(Tj);
    free(Tx);
    return rc;
}

/* max |A_ij - A_ji| <= tol max|A_ij| (binary search of the mirrored entry). */
static int is_symmetric(const pd_sparse *A)
{
    pd_matrix v = pd_sparse_view(A);
    double amax = 0.0, dmax = 0.0;
    for (int k = 0; k < A->nnz; k++)
        amax = fmax(amax, fabs(A->values[k]));
    /* each stored A_ij against A_ji */
    for (int j = 0; j < A->cols; j++)
        for (int k = A->colptr[j]; k < A->colptr[j + 1]; k++)
            dmax = fmax(dmax, fabs(A->values[k] - pd_matrix_get(&v, j, A->rowind[k])));
    return dmax <= CHOL_SYMMETRY_TOL * amax;
}

/* U = L^T by counting sort: row indices come out increasing. */
static int transpose_L(chol_data *d)
{
    int n = d->n, nz = d->Lp[n];
    d->Up = calloc((size_t)n + 1, sizeof(int));
    d->Ui = malloc((size_t)nz * sizeof(int));
    d->Ux = malloc((size_t)nz * sizeof(double));
    int *next = malloc(((size_t)n + 1) * sizeof(int));
    if (!d->Up || !d->Ui || !d->Ux || !next) {
        free(next);
        return PD_ENOMEM;
    }
    /* each row's count of L: the sizes of U's columns */
    for (int k = 0; k < nz; k++)
        d->Up[d->Li[k] + 1]++;
    for (int i = 0; i < n; i++)
        d->Up[i + 1] += d->Up[i];
    /* Up: the running sums of L's row counts; next: each column of U's next free place */
    memcpy(next, d->Up, ((size_t)n + 1) * sizeof(int));
    for (int j = 0; j < n; j++)
        for (int k = d->Lp[j]; k < d->Lp[j + 1]; k++) {
            /* L_ij = U_ji: columns j of L in order, so each row of U fills with j increasing */
            int p = next[d->Li[k]]++;
            d->Ui[p] = j;
            d->Ux[p] = d->Lx[k];
        }
    free(next);
    return PD_OK;
}

/* L (simplicial LL^T) and P copied out of CHOLMOD's factor. */
static int copy_factor(chol_data *d, const cholmod_factor *L)
{
    const int *p = L->p, *i = L->i, *nz = L->nz, *perm = L->Perm;
    const double *x = L->x;
    int n = d->n, total = 0;
    for (int j = 0; j < n; j++)
        total += nz[j]; /* L's entries, packed or not */
    d->Lp = malloc(((size_t)n + 1) * sizeof(int));
    d->Li = malloc((size_t)total * sizeof(int));
    d->Lx = malloc((size_t)total * sizeof(double));
    d->perm = malloc((size_t)n * sizeof(int));
    d->pinv = malloc((size_t)n * sizeof(int));
    if (!d->Lp || !d->Li || !d->Lx || !d->perm || !d->pinv)
        return PD_ENOMEM;
    d->Lp[0] = 0;
    for (int j = 0; j < n; j++) {
        /* column j of L, diagonal first; the order P, and pinv its inverse */
        memcpy(d->Li + d->Lp[j], i + p[j], (size_t)nz[j] * sizeof(int));
        memcpy(d->Lx + d->Lp[j], x + p[j], (size_t)nz[j] * sizeof(double));
        d->Lp[j + 1] = d->Lp[j] + nz[j];
        d->perm[j] = perm[j];
        d->pinv[perm[j]] = j;
    }
    return PD_OK;
}

/* CHOLMOD: AMD ordering and a simplicial LL^T of the lower triangle. */
static int cholesky(chol_data *d, pd_sparse *A, pd_err *err)
{
    cholmod_common c;
    cholmod_factor *L = NULL;
    int rc = PD_OK;
    cholmod_start(&c);
    c.print = 0; /* the library never prints */
    c.error_handler = NULL;
    c.supernodal = CHOLMOD_SIMPLICIAL; /* plain columns to copy out */
    c.final_ll = 1;                    /* L L^T, not L D L^T */
    c.final_pack = 1;
    c.final_monotonic = 1;
    /* A's lower triangle (stype -1), a view of its arrays, not a copy */
    cholmod_sparse As = {.nrow = (size_t)A->rows,
                         .ncol = (size_t)A->cols,
                         .nzmax = (size_t)(A->nnz > 0 ? A->nnz : 1),
                         .p = A->colptr,
                         .i = A->rowind,
                         .x = A->values,
                         .stype = -1,
                         .itype = CHOLMOD_INT,
                         .xtype = CHOLMOD_REAL,
                         .dtype = CHOLMOD_DOUBLE,
                         .sorted = 1,
                         .packed = 1};
    L = cholmod_analyze(&As, &c); /* AMD ordering, symbolic factor */
    if (L)
        cholmod_factorize(&As, L, &c);
    if (!L || c.status == CHOLMOD_OUT_OF_MEMORY)
        rc = pd_err_set(err, PD_ENOMEM, "CHOLMOD: out of memory for n = %d", d->n);
    /* minor < n: a non-positive pivot at column minor */
    else if (c.status == CHOLMOD_NOT_POSDEF || L->minor < L->n)
        rc = pd_err_set(err, PD_ESINGULAR,
                        "the iteration matrix M + h theta C + h^2 theta^2 K is not positive "
                        "definite (CHOLMOD stopped at column %d)",
                        (int)L->minor);
    else if (c.status < CHOLMOD_OK || L->is_super || !L->is_ll)
        rc = pd_err_set(err, PD_ENUMERICAL, "CHOLMOD: factorization failed (status %d)", c.status);
    else if (copy_factor(d, L) || transpose_L(d))
        rc = pd_err_set(err, PD_ENOMEM, "factor: out of memory for the Cholesky factor");
    cholmod_free_factor(&L, &c);
    cholmod_finish(&c);
    return rc;
}

/* A growing compressed-column matrix (setup only). */
typedef struct col_builder {
    int *p, *i;
    double *x;
    long nz, cap;
} col_builder;

static int cb_push(col_builder *b, int row, double val)
{
    if (b->nz == b->cap) {
        long cap = 2 * b->cap + 64; /* geometric growth */
        int *ni = realloc(b->i, (size_t)cap * sizeof(int));
        if (ni)
            b->i = ni;
        double *nx = realloc(b->x, (size_t)cap * sizeof(double));
        if (nx)
            b->x = nx;
        /* a failed realloc keeps the old block (freed with the
         * builder); int indices bound the size */
        if (!ni || !nx || cap > 2147483647L)
            return PD_ENOMEM;
        b->cap = cap;
    }
    b->i[b->nz] = row;
    b->x[b->nz++] = val;
    return PD_OK;
}

/* Sort rows of the entries [from, nz) (insertion: columns are short). */
static void cb_sort_tail(col_builder *b, long from)
{
    for (long k = from + 1; k < b->nz; k++) {
        int r = b->i[k];
        double v = b->x[k];
        long p = k;
        /* entry k inserted among [from, k), rows increasing */
        for (; p > from && b->i[p - 1] > r; p--) {
            b->i[p] = b->i[p - 1];
            b->x[p] = b->x[p - 1];
        }
        b->i[p] = r;
        b->x[p] = v;
    }
}

/* One column of Z: What^-1 W_a by two sparse triangular solves. */
static int z_column(chol_data *d, const pd_sparse *W, int a, int *xi, double *x, int *bi,
                    double *bx, col_builder *Z)
{
    int n = d->n, nb = 0;
    for (int k = W->colptr[a]; k < W->colptr[a + 1]; k++) { /* b = P W_a */
        bi[nb] = d->pinv[W->rowind[k]];
        bx[nb++] = W->values[k];
    }
    /* B: P W_a as a one-column sparse matrix */
    int bp[2] = {0, nb};
    cs_di B = {.nzmax = nb > 0 ? nb : 1, .m = n, .n = 1, .p = bp, .i = bi, .x = bx, .nz = -1};
    cs_di Lc = {.nzmax = d->Lp[n], .m = n, .n = n, .p = d->Lp, .i = d->Li, .x = d->Lx, .nz = -1};
    cs_di Uc = {.nzmax = d->Up[n], .m = n, .n = n, .p = d->Up, .i = d->Ui, .x = d->Ux, .nz = -1};
    int top = cs_di_spsolve(&Lc, &B, 0, xi, x, NULL, 1); /* y = L^-1 b */
    if (top < 0)
        return PD_ENUMERICAL;
    /* the reach of y = L^-1 b, gathered as the next right-hand side */
    nb = 0;
    for (int p = top; p < n; p++) {
        bi[nb] = xi[p];
        bx[nb++] = x[xi[p]];
    }
    bp[1] = nb;
    B.nzmax = nb > 0 ? nb : 1;
    top = cs_di_spsolve(&Uc, &B, 0, xi, x, NULL, 0); /* z = L^-T y */
    if (top < 0)
        return PD_ENUMERICAL;
    /* Z_a = P^T z without its exact zeros, rows sorted */
    long from = Z->nz;
    for (int p = top; p < n; p++)
        if (x[xi[p]] != 0.0 && cb_push(Z, d->perm[xi[p]], x[xi[p]]))
            return PD_ENOMEM;
    cb_sort_tail(Z, from);
    return PD_OK;
}

/* Z = What^-1 W (n x m), sparse. */
static int form_z(chol_data *d, const pd_sparse *W, pd_err *err)
{
    int n = d->n, rc = PD_OK;
    col_builder Z = {0};
    /* cs_spsolve's workspaces (xi of 2 n, x of n) and a column's indices and values */
    int *xi = malloc(2 * (size_t)n * sizeof(int)), *bi = malloc((size_t)n * sizeof(int));
    double *x = calloc((size_t)n, sizeof(double)), *bx = malloc((size_t)n * sizeof(double));
    d->Zp = malloc(((size_t)d->m + 1) * sizeof(int));
    if (!xi || !bi || !x || !bx || !d->Zp)
        rc = PD_ENOMEM;
    for (int a = 0; a < d->m && !rc; a++) {
        d->Zp[a] = (int)Z.nz;
        rc = z_column(d, W, a, xi, x, bi, bx, &Z);
    }
    if (!rc)
        d->Zp[d->m] = (int)Z.nz;
    d->Zi = Z.i;
    d->Zx = Z.x;
    free(xi);
    free(bi);
    free(x);
    free(bx);
    if (rc == PD_ENOMEM)
        return pd_err_set(err, rc, "factor: out of memory for What^-1 W (%ld entries)", Z.nz);
    if (rc)
        return pd_err_set(err, rc, "factor: sparse triangular solve failed");
    return PD_OK;
}

/* D = W^T Z (m x m), sparse: column b gathers W_a^T Z_b over the contacts a
 * that touch a row of Z_b (Wt lists the contacts of each dof). */
static int form_d(chol_data *d, const pd_sparse *Wt, pd_err *err)
{
    int m = d->m, rc = PD_OK;
    col_builder D = {0};
    double *acc = pd_calloc(m, sizeof(double));
    int *mark = pd_malloc(m, sizeof(int));
    d->Dp = malloc(((size_t)m + 1) * sizeof(int));
    if (!acc || !mark || !d->Dp)
        rc = PD_ENOMEM;
    for (int a = 0; a < m && !rc; a++)
        mark[a] = -1; /* in no column yet */
    /* column b: D_ab = sum_i W_ia Z_ib over the dofs i of Z_b and the contacts a on them (Wt) */
    for (int b = 0; b < m && !rc; b++) {
        long from = D.nz;
        d->Dp[b] = (int)D.nz;
        for (int k = d->Zp[b]; k < d->Zp[b + 1] && !rc; k++) {
            int i = d->Zi[k];
            for (int q = Wt->colptr[i]; q < Wt->colptr[i + 1] && !rc; q++) {
                int a = Wt->rowind[q];
                if (mark[a] != b) { /* a new row of column b */
                    mark[a] = b;
                    acc[a] = 0.0;
                    rc = cb_push(&D, a, 0.0);
                }
                acc[a] += Wt->values[q] * d->Zx[k];
            }
        }
        /* the sums into their entries, then the rows sorted */
        for (long k = from; k < D.nz; k++)
            D.x[k] = acc[D.i[k]];
        cb_sort_tail(&D, from);
    }
    if (!rc)
        d->Dp[m] = (int)D.nz;
    d->Di = D.i;
    d->Dx = D.x;
    free(acc);
    free(mark);
    return rc ? pd_err_set(err, rc, "factor: out of memory for the Delassus matrix") : PD_OK;
}

/* W and W^T as owned sparse matrices (any storage kind of the model). */
static int contact_maps(const pd_model *md, pd_sparse *W, pd_sparse *Wt, pd_err *err)
{
    int rc = assemble(md, 0.0, 1, W, err);
    if (rc)
        return rc;
    long nt = W->nnz;
    int *Ti = malloc((size_t)(nt + 1) * sizeof(int)), *Tj = malloc((size_t)(nt + 1) * sizeof(int));
    if (!Ti || !Tj)
        rc = pd_err_set(err, PD_ENOMEM, "factor: out of memory for W^T");
    /* W^T's triplets: (a, i) for each entry W_ia */
    for (int a = 0; a < W->cols && !rc; a++)
        for (int k = W->colptr[a]; k < W->colptr[a + 1]; k++) {
            Ti[k] = a;
            Tj[k] = W->rowind[k];
        }
    if (!rc)
        rc = pd_sparse_from_triplets(Wt, md->m, md->n, nt, Ti, Tj, W->values, err);
    free(Ti);
    free(Tj);
    return rc;
}

static int chol_setup(pd_factor *f, pd_err *err)
{
    const pd_model *md = f->model;
    pd_sparse A = {0}, W = {0}, Wt = {0};
    chol_data *d = calloc(1, sizeof *d);
    int rc;
    f->data = d;
    if (!d)
        return pd_err_set(err, PD_ENOMEM, "factor: out of memory");
    d->n = md->n;
    d->m = md->m;
    d->pos = pd_malloc(md->m, sizeof(int));
    d->work = malloc((size_t)md->n * sizeof(double));
    if (!d->pos || !d->work)
        return pd_err_set(err, PD_ENOMEM, "factor: out of memory for n = %d", md->n);
    for (int a = 0; a < md->m; a++)
        d->pos[a] = -1; /* no contact placed */
    /* What = M + h theta C + h^2 theta^2 K, symmetric to 1e-12 of its largest entry */
    if (!(rc = assemble(md, f->h * f->theta, 0, &A, err))) {
        if (!is_symmetric(&A))
            rc = pd_err_set(err, PD_EINVAL,
                            "the iteration matrix M + h theta C + h^2 theta^2 K is not symmetric: "
                            "the cholmod factor needs a symmetric model (use the dense factor)");
        else
            rc = cholesky(d, &A, err);
    }
    /* Z = What^-1 W, then D = W^T Z */
    if (!rc && md->m > 0 && !(rc = contact_maps(md, &W, &Wt, err)) && !(rc = form_z(d, &W, err)))
        rc = form_d(d, &Wt, err);
    if (!rc)
        f->delassus_nnz = md->m > 0 ? d->Dp[md->m] : 0; /* D's entries */
    pd_sparse_free(&A);
    pd_sparse_free(&W);
    pd_sparse_free(&Wt);
    return rc;
}

/* x = P^T L^-T L^-1 P x. */
static void chol_solve(const pd_factor *f, double *x)
{
    const chol_data *d = f->data;
    int n = d->n;
    double *y = d->work;
    for (int k = 0; k < n; k++)
        y[k] = x[d->perm[k]];     /* y = P x */
    for (int j = 0; j < n; j++) { /* L y = P x, diagonal first */
        int p = d->Lp[j];
        /* y_j /= L_jj, then y_i -= L_ij y_j below it */
        double yj = y[j] /= d->Lx[p];
        if (yj != 0.0) /* nothing to eliminate */
            for (p++; p < d->Lp[j + 1]; p++)
                y[d->Li[p]] -= d->Lx[p] * yj;
    }
    for (int j = n - 1; j >= 0; j--) { /* L^T z = y, a dot product per column of L */
        double s = y[j];
        int p = d->Lp[j];
        for (int q = p + 1; q < d->Lp[j + 1]; q++)
            s -= d->Lx[q] * y[d->Li[q]];
        y[j] = s / d->Lx[p];
    }
    for (int k = 0; k < n; k++)
        x[d->perm[k]] = y[k]; /* x = P^T z */
}

/* v += Z[:, idx] P. */
static void chol_add_impulse(const pd_factor *f, const int *idx, int nI, const double *P, double *v)
{
    const chol_data *d = f->data;
    for (int r = 0; r < nI; r++) {
        /* v += Z_a P_a over the stored entries of Z_a */
        double pr = P[r];
        if (pr != 0.0)
            for (int k = d->Zp[idx[r]]; k < d->Zp[idx[r] + 1]; k++)
                v[d->Zi[k]] += d->Zx[k] * pr;
    }
}

static void chol_delassus_dense(const pd_factor *f, const int *idx, int nI, double *D)
{
    const chol_data *d = f->data;
    /* pos: each chosen contact's row; D_II gathered from D's columns idx */
    memset(D, 0, (size_t)nI * (size_t)nI * sizeof(double));
    for (int r = 0; r < nI; r++)
        d->pos[idx[r]] = r;
    for (int s = 0; s < nI; s++)
        for (int k = d->Dp[idx[s]]; k < d->Dp[idx[s] + 1]; k++)
            if (d->pos[d->Di[k]] >= 0)
                D[d->pos[d->Di[k]] + (size_t)s * nI] = d->Dx[k];
    for (int r = 0; r < nI; r++)
        d->pos[idx[r]] = -1; /* cleared for the next call */
}

static int chol_delassus_csc(const pd_factor *f, const int *idx, int nI, int *colptr, int *rowind,
                             double *values, int *map)
{
    const chol_data *d = f->data;
    int nz = 0;
    for (int r = 0; r < nI; r++)
        d->pos[idx[r]] = r;
    for (int s = 0; s < nI; s++) {
        /* column s: the entries of D's column idx[s] whose rows are chosen */
        colptr[s] = nz;
        for (int k = d->Dp[idx[s]]; k < d->Dp[idx[s] + 1]; k++)
            if (d->pos[d->Di[k]] >= 0) {
                if (map)
                    map[k] = nz;
                rowind[nz] = d->pos[d->Di[k]];
                values[nz++] = d->Dx[k];
            }
    }
    colptr[nI] = nz;
    for (int r = 0; r < nI; r++)
        d->pos[idx[r]] = -1; /* cleared for the next call */
    return nz;
}

/* D's entry (column a, row b): a search of column a's rows. */
static long chol_delassus_at(const pd_factor *f, int a, int b)
{
    const chol_data *d = f->data;
    for (int k = d->Dp[a]; k < d->Dp[a + 1]; k++)
        if (d->Di[k] == b)
            return k;
    return -1;
}

const pd_factor_type pd_factor_cholmod_type = {
    .name = "cholmod",
    .kind = PD_FACTOR_CHOLMOD,
    .setup = chol_setup,
    .solve = chol_solve,
    .add_impulse = chol_add_impulse,
    .delassus_dense = chol_delassus_dense,
    .delassus_csc = chol_delassus_csc,
    .delassus_at = chol_delassus_at,
    .release = chol_release,
};
