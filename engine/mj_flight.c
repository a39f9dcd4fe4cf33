/* mj_flight.c — exact flights for Moreau–Jean to a tolerance: linear
 * structures under a piecewise forcing F(t) = b f(t).
 *
 *   blocks     the dofs that M, C, K couple (one structure each in a scene); blocks
 *              alike (the same M, C, K, b) share one kind of table
 *   augmented  per block x = [q; v] and the forcing's state z = [A sin(w t + phi),
 *              A cos(w t + phi), c0 + c1 (t - ts), c1], f = z0 + z2:
 *                x' = [[0, I], [-M^-1 K, -M^-1 C]] x + [0; M^-1 b] (z0 + z2),
 *                z' = [w z1, -w z0, z3, 0]            (A~, na = 2 s + 4)
 *   ladder     E_k = exp(A~ h_k) - I: the finest level's by its Taylor series, then
 *              E_k-1 = 2 E_k + E_k^2 (the increment form keeps tiny steps exact:
 *              x+ = x + E_k [x; z]) on the first 2 s rows, the forcing's own
 *              block Z_k = exp(A_z h_k) - I in closed form
 *   a span     the free flights of several levels in turn (the binary digits of
 *              a stretch of the grid), one step when no contact shut at its end
 *   a step     the free flight of every block, z in closed form; contacts active
 *              when their gap is shut at the step's start (within sim_gap, the scale
 *              below which the reference takes contacts as closed) or at the free
 *              flight's end; impulses P at mid-step (the exact-flow counterpart of theta =
 *              1/2, which keeps a held gap shut to O(h^3)):
 *                v+ = v_free + Phi_vv(h/2) M^-1 W P,  q+ = q_free + Phi_qv(h/2) M^-1 W P,
 *                w = W^T v+ + e U_k >= 0 ⊥ P >= 0,  D = W^T Phi_vv(h/2) M^-1 W
 * The tables are formed with the object (one table a level a kind); a step
 * allocates nothing. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mj.h"
#include "pd_alloc.h"

#define FL_TAYLOR_MAX 40 /* terms of the finest level's series, at most */

/* A kind of block: its tables. */
typedef struct fl_kind {
    int s, na;       /* dofs; 2 s + 4 */
    double *E;       /* levels 0..L+1: the first 2 s rows of E_k (2 s x na, by columns) */
    double *Minv;    /* s x s: M^-1 */
    double *Av;      /* s x na: the rows of A~ for v' (the accelerations) */
    double *PV, *PQ; /* levels 0..L: Phi_vv(h_k/2) M^-1 and Phi_qv(h_k/2) M^-1 (s x s), an
                        impulse's response at mid-step */
    double wmax;     /* a bound of its highest natural frequency */
} fl_kind;

/* A block: its kind and dofs. */
typedef struct fl_block {
    int kind, s;
    int *dofs; /* s dofs, increasing */
} fl_block;

struct mj_flight {
    const pd_piecewise_force *F;
    double w;             /* the sinusoids' frequency */
    int L;                /* levels 0..L + 1 */
    double *h, *cm1, *sw; /* L + 2: h_k, cos(w h_k) - 1, sin(w h_k) */
    int nblocks, nkinds;
    fl_block *blocks;
    fl_kind *kinds;
    int *block_of, *at; /* n: each dof's block, its place in it */
    int *dofs;          /* n: the blocks' dofs, end to end */
    unsigned *touched;  /* nblocks: the stamp of the last visit */
    unsigned *cmark;    /* m: the stamp of the last visit */
    unsigned stamp;
    int *pos;           /* m: place of a contact in the active set, or -1 */
    int *rows;          /* m: a column's rows (column_rows, sdof_column) */
    double *vals;       /* m: its values (sdof_column) */
    double *r;          /* n: W P */
    double *x, *dx, *y; /* 2 smax + 4 */
    int sdofs;          /* every block one dof (rows of SDOFs): the flights by dofs */
    int *kind_d;        /* n (sdofs): each dof's kind */
    double *Ac;         /* 6 nkinds (sdofs): each kind's flight over a span (sdof_compose) */
    double *zs;         /* 4 (L + 2): the forcing's state before each level of a span */
};

/* ---- dense helpers ---------------------------------------------------------- */

/* C = A B for na x na column-major A, B (C distinct) that are block upper
 * triangular over [rows | na - rows] (A~, its powers and exponentials: the
 * forcing's states move by themselves).  By columns, C_:j = sum_l A_:l B_lj
 * with l in order (each C_ij the same sum as a row times a column, bit for
 * bit), skipping the terms of zero B_lj and, for l < rows, A's zero rows
 * below: the sums of a column run side by side, not in one chain. */
static void matmul(int na, int rows, const double *A, const double *B, double *C)
{
    for (int j = 0; j < na; j++) {
        double *c = C + (size_t)j * na;
        for (int i = 0; i < na; i++)
            c[i] = 0.0;
        for (int l = 0; l < na; l++) {
            double b = B[l + (size_t)j * na];
            if (b == 0.0)
                continue;
            const double *a = A + (size_t)l * na;
            for (int i = 0, end = l < rows ? rows : na; i < end; i++)
                c[i] += a[i] * b;
        }
    }
}

/* ||A||_1 (the largest column sum). */
static double norm1(int na, const double *A)
{
    double best = 0.0;
    for (int j = 0; j < na; j++) {
        double sum = 0.0;
        for (int i = 0; i < na; i++)
            sum += fabs(A[i + (size_t)j * na]);
        best = fmax(best, sum);
    }
    return best;
}

/* ---- blocks --------------------------------------------------------------- */

static int find_root(int *parent, int i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]]; /* path halving */
    return i;
}

/* Join the dofs every stored off-diagonal entry of A couples. */
static void join_entries(const pd_matrix *A, int *parent)
{
    double v;
    for (int j = 0; j < A->cols; j++)
        for (int p = -1, i; mj_col_next(A, j, &p, &i, &v);) {
            if (i == j || v == 0.0)
                continue;
            int a = find_root(parent, i), b = find_root(parent, j);
            /* the smaller root stays: a root is its block's smallest dof */
            if (a != b)
                parent[a < b ? b : a] = a < b ? a : b;
        }
}

/* Blocks from the coupling of M, C, K: block_of, at, dofs and the blocks'
 * sizes and dof lists (dofs increasing in each). */
static int find_blocks(const pd_model *md, mj_flight *fl)
{
    int n = md->n;
    int *parent = malloc((size_t)n * sizeof(int)), *first = malloc((size_t)n * sizeof(int));
    int rc = PD_ENOMEM;
    if (!parent || !first)
        goto done;
    for (int i = 0; i < n; i++)
        parent[i] = i;
    /* union-find: each dof alone, then joined where M, C or K couples two */
    join_entries(&md->M, parent);
    join_entries(&md->C, parent);
    join_entries(&md->K, parent);
    fl->nblocks = 0;
    for (int i = 0; i < n; i++) /* roots are their block's smallest dof */
        if (find_root(parent, i) == i)
            first[i] = fl->nblocks++;
    if (!(fl->blocks = calloc((size_t)fl->nblocks, sizeof *fl->blocks)))
        goto done;
    for (int i = 0; i < n; i++) {
        /* each dof's block, and its place there in increasing order */
        int b = first[find_root(parent, i)];
        fl->block_of[i] = b;
        fl->at[i] = fl->blocks[b].s++;
    }
    /* the blocks' dof lists end to end in fl->dofs */
    for (int b = 0, off = 0; b < fl->nblocks; b++) {
        fl->blocks[b].dofs = fl->dofs + off;
        off += fl->blocks[b].s;
    }
    for (int i = 0; i < n; i++)
        fl->blocks[fl->block_of[i]].dofs[fl->at[i]] = i;
    rc = PD_OK;
done:
    free(parent);
    free(first);
    return rc;
}

/* 1 when blocks a and b have the same M, C, K and b entries. */
static int same_block(const pd_model *md, const pd_piecewise_force *F, const fl_block *a,
                      const fl_block *b)
{
    if (a->s != b->s)
        return 0;
    for (int i = 0; i < a->s; i++) {
        if (F->b[a->dofs[i]] != F->b[b->dofs[i]])
            return 0;
        /* M, C, K entry by entry, exactly: blocks alike share their tables bit for bit */
        for (int j = 0; j < a->s; j++) {
            int ai = a->dofs[i], aj = a->dofs[j], bi = b->dofs[i], bj = b->dofs[j];
            if (pd_matrix_get(&md->M, ai, aj) != pd_matrix_get(&md->M, bi, bj) ||
                pd_matrix_get(&md->C, ai, aj) != pd_matrix_get(&md->C, bi, bj) ||
                pd_matrix_get(&md->K, ai, aj) != pd_matrix_get(&md->K, bi, bj))
                return 0;
        }
    }
    return 1;
}

/* A hash of a block's entries (blocks alike hash alike). */
static uint64_t block_hash(const pd_model *md, const pd_piecewise_force *F, const fl_block *bl)
{
    uint64_t h = 1469598103934665603ull ^ (uint64_t)bl->s; /* the size mixed in */
    for (int i = 0; i < bl->s; i++)
        for (int j = 0; j < bl->s; j++) {
            int di = bl->dofs[i], dj = bl->dofs[j];
            double v[4] = {pd_matrix_get(&md->M, di, dj), pd_matrix_get(&md->C, di, dj),
                           pd_matrix_get(&md->K, di, dj), i == j ? F->b[di] : 0.0};
            for (int k = 0; k < 4; k++) {
                uint64_t bits;
                memcpy(&bits, &v[k], sizeof bits);
                h = (h ^ bits) * 1099511628211ull; /* FNV-1a's step over the entries' bits */
            }
        }
    return h;
}

/* ---- the tables of a kind ---------------------------------------------------- */

/* A~ of block bl (na x na, by columns) and M^-1 into the kind. */
static int augmented(const pd_model *md, const mj_flight *fl, const fl_block *bl, fl_kind *kd,
                     double *A, pd_err *err)
{
    int s = bl->s, na = kd->na;
    double *LU = calloc((size_t)s * s, sizeof(double));
    int *perm = calloc((size_t)s, sizeof(int));
    if (!LU || !perm) {
        free(LU);
        free(perm);
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for a block of %d dofs", s);
    }
    for (int j = 0; j < s; j++)
        for (int i = 0; i < s; i++)
            LU[i + (size_t)j * s] = pd_matrix_get(&md->M, bl->dofs[i], bl->dofs[j]);
    /* the block's M, LU with partial pivoting */
    int rc = pd_dense_lu(s, LU, s, perm, 1e-14);
    if (rc) {
        free(LU);
        free(perm);
        return pd_err_set(err, PD_ESINGULAR,
                          "Moreau-Jean: the mass matrix of the block of dof "
                          "%d is singular",
                          bl->dofs[0]);
    }
    /* M^-1 by columns, then -M^-1 K and -M^-1 C into A~ */
    memset(A, 0, (size_t)na * na * sizeof(double));
    for (int j = 0; j < s; j++) {
        double *mj_col = kd->Minv + (size_t)j * s;
        for (int i = 0; i < s; i++)
            mj_col[i] = i == j ? 1.0 : 0.0;
        /* M x = e_j: column j of M^-1 */
        pd_dense_lu_solve(s, LU, s, perm, mj_col);
    }
    for (int j = 0; j < s; j++) {
        /* A~'s rows s..2 s - 1: -M^-1 K in the q columns, -M^-1 C in the v columns */
        for (int which = 0; which < 2; which++) {
            const pd_matrix *X = which ? &md->C : &md->K;
            for (int i = 0; i < s; i++) {
                double sum = 0.0;
                for (int l = 0; l < s; l++)
                    sum += kd->Minv[i + (size_t)l * s] * pd_matrix_get(X, bl->dofs[l], bl->dofs[j]);
                A[s + i + (size_t)(which ? s + j : j) * na] = -sum;
            }
        }
        A[j + (size_t)(s + j) * na] = 1.0; /* q' = v */
    }
    for (int i = 0; i < s; i++) {
        double sum = 0.0;
        for (int l = 0; l < s; l++)
            sum += kd->Minv[i + (size_t)l * s] * fl->F->b[bl->dofs[l]];
        A[s + i + (size_t)(2 * s) * na] = sum;     /* z0 */
        A[s + i + (size_t)(2 * s + 2) * na] = sum; /* z2 */
    }
    A[2 * s + (size_t)(2 * s + 1) * na] = fl->w;   /* z0' = w z1 */
    A[2 * s + 1 + (size_t)(2 * s) * na] = -fl->w;  /* z1' = -w z0 */
    A[2 * s + 2 + (size_t)(2 * s + 3) * na] = 1.0; /* z2' = z3 */
    free(LU);
    free(perm);
    return PD_OK;
}

/* Gershgorin's bound of the block's highest natural frequency, sqrt of
 * max_i sum_j |(M^-1 K)_ij|, read off A~. */
static double block_wmax(const fl_kind *kd, const double *A)
{
    int s = kd->s, na = kd->na;
    double best = 0.0;
    for (int i = 0; i < s; i++) {
        double sum = 0.0;
        for (int j = 0; j < s; j++)
            sum += fabs(A[s + i + (size_t)j * na]);
        best = fmax(best, sum); /* max row sum of |M^-1 K| >= rho(M^-1 K) = w_max^2 */
    }
    return sqrt(best);
}

/* One level up the ladder on the first 2 s rows of E_k = [[X, Y], [0, Z_k]]
 * (Z_k = exp(A_z h_k) - I, the forcing's own, in closed form: rows
 * [cm1, sw, 0, 0], [-sw, cm1, 0, 0], [0, 0, 0, h], 0): E_k-1 = 2 E_k + E_k^2,
 * whose rows are X' = 2 X + X X and Y' = 2 Y + X Y + Y Z_k.  T and T1 are
 * rows x na by columns (leading dimension rows), T1 distinct. */
static void level_up(const mj_flight *fl, int k, int rows, const double *T, double *T1)
{
    double cm1 = fl->cm1[k], sw = fl->sw[k], h = fl->h[k];
    if (rows == 2) { /* an SDOF: X = [[a, c], [b, d]] by columns, the same sums unrolled */
        double a = T[0], b = T[1], c = T[2], d = T[3];
        for (int j = 0; j < 6; j++) {
            double t0 = T[2 * j], t1 = T[2 * j + 1];
            T1[2 * j] = 2.0 * t0 + a * t0 + c * t1;
            T1[2 * j + 1] = 2.0 * t1 + b * t0 + d * t1;
        }
        for (int i = 0; i < 2; i++) {
            double y0 = T[4 + i], y1 = T[6 + i], y2 = T[8 + i];
            T1[4 + i] += y0 * cm1 - y1 * sw;
            T1[6 + i] += y0 * sw + y1 * cm1;
            T1[10 + i] += y2 * h;
        }
        return;
    }
    /* T1 = 2 T + X T over every column (X T = [X X, X Y]) */
    for (int j = 0; j < rows + 4; j++) {
        const double *t = T + (size_t)j * rows;
        double *c = T1 + (size_t)j * rows;
        for (int i = 0; i < rows; i++)
            c[i] = 2.0 * t[i];
        for (int l = 0; l < rows; l++) {
            double b = t[l];
            if (b == 0.0)
                continue;
            const double *x = T + (size_t)l * rows; /* column l of X */
            for (int i = 0; i < rows; i++)
                c[i] += x[i] * b;
        }
    }
    /* + Y Z_k: column 0 Y_0 cm1 - Y_1 sw, column 1 Y_0 sw + Y_1 cm1, column 3 Y_2 h */
    const double *Y = T + (size_t)rows * rows;
    double *Y1 = T1 + (size_t)rows * rows;
    for (int i = 0; i < rows; i++) {
        double y0 = Y[i], y1 = Y[rows + i], y2 = Y[2 * rows + i];
        Y1[i] += y0 * cm1 - y1 * sw;
        Y1[rows + i] += y0 * sw + y1 * cm1;
        Y1[3 * rows + i] += y2 * h;
    }
}

/* E at every level: the finest one's series, then E_k-1 = 2 E_k + E_k^2
 * on the first 2 s rows (level_up), which are kept. */
static int ladder(const mj_flight *fl, fl_kind *kd, const double *A, pd_err *err)
{
    int na = kd->na, rows = 2 * kd->s, L = fl->L;
    size_t nn = (size_t)na * na, lev = (size_t)rows * na;
    double *E = malloc(nn * sizeof(double)), *T = malloc(nn * sizeof(double)),
           *U = malloc(nn * sizeof(double));
    if (!E || !T || !U) {
        free(E);
        free(T);
        free(U);
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for a block's ladder");
    }
    /* the finest level: E = sum_j>=1 (A h)^j / j! */
    double hf = fl->h[L + 1]; /* h_L+1, the finest */
    for (size_t i = 0; i < nn; i++)
        E[i] = T[i] = A[i] * hf;
    /* T = (A h)^j / j! added while it counts beyond 1e-18 of E, FL_TAYLOR_MAX terms at most */
    for (int j = 2; j <= FL_TAYLOR_MAX && norm1(na, T) > 1e-18 * fmax(norm1(na, E), 1e-300); j++) {
        matmul(na, rows, T, A, U);
        for (size_t i = 0; i < nn; i++) {
            T[i] = U[i] * hf / j;
            E[i] += T[i];
        }
    }
    /* its first 2 s rows, then each coarser level's from the finer one's */
    double *top = kd->E + (size_t)(L + 1) * lev;
    for (int c = 0; c < na; c++)
        for (int r = 0; r < rows; r++)
            top[r + (size_t)c * rows] = E[r + (size_t)c * na];
    for (int k = L + 1; k > 0; k--)
        level_up(fl, k, rows, kd->E + (size_t)k * lev, kd->E + (size_t)(k - 1) * lev);
    /* an overflow at the coarse levels (large w h) refuses the run: a smaller h
     * (level 0 is formed from every finer one: a NaN or inf anywhere shows there) */
    int finite = 1;
    for (size_t i = 0; i < lev; i++)
        finite &= isfinite(kd->E[i]);
    free(E);
    free(T);
    free(U);
    return finite ? PD_OK
                  : pd_err_set(err, PD_ENUMERICAL,
                               "Moreau-Jean: the exact flight of a block of "
                               "%d dofs overflows at the coarsest step (a smaller h)",
                               kd->s);
}

/* The first 2 s rows of E_k of kind kd. */
static const double *level_E(const fl_kind *kd, int k)
{
    return kd->E + (size_t)k * 2 * kd->s * kd->na;
}

/* PV_k = Phi_vv(h_k / 2) M^-1 = (I + E_k+1,vv) M^-1 and PQ_k = E_k+1,qv M^-1
 * for every level k = 0..L. */
static int impulse_responses(const mj_flight *fl, fl_kind *kd, pd_err *err)
{
    int s = kd->s, rows = 2 * s;
    size_t ss = (size_t)s * s;
    if (!(kd->PV = malloc(2 * (size_t)(fl->L + 1) * ss * sizeof(double))))
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for a block's tables");
    kd->PQ = kd->PV + (size_t)(fl->L + 1) * ss;
    for (int k = 0; k <= fl->L; k++) {
        /* h_k+1 = h_k / 2: Phi(h_k / 2) = I + E_k+1 */
        const double *E = level_E(kd, k + 1);
        double *PV = kd->PV + (size_t)k * ss, *PQ = kd->PQ + (size_t)k * ss;
        for (int j = 0; j < s; j++)
            for (int i = 0; i < s; i++) {
                double v = 0.0, q = 0.0;
                for (int l = 0; l < s; l++) {
                    double ml = kd->Minv[l + (size_t)j * s];
                    v += ((i == l ? 1.0 : 0.0) + E[s + i + (size_t)(s + l) * rows]) * ml;
                    q += E[i + (size_t)(s + l) * rows] * ml; /* E_qv M^-1 */
                }
                PV[i + (size_t)j * s] = v;
                PQ[i + (size_t)j * s] = q;
            }
    }
    return PD_OK;
}

/* The kinds: blocks alike share one; each kind's tables. */
static int form_kinds(const pd_model *md, mj_flight *fl, pd_err *err)
{
    int nb = fl->nblocks, rc = PD_OK;
    uint64_t *hash = malloc((size_t)nb * sizeof(uint64_t));
    int *rep = malloc((size_t)nb * sizeof(int)); /* each kind's first block */
    fl->kinds = calloc((size_t)nb, sizeof *fl->kinds);
    if (!hash || !rep || !fl->kinds) {
        rc = pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for %d blocks", nb);
        goto done;
    }
    fl->nkinds = 0;
    for (int b = 0; b < nb; b++) { /* a scene's kinds are few: compare with each */
        fl_block *bl = &fl->blocks[b];
        hash[b] = block_hash(md, fl->F, bl);
        bl->kind = -1;
        for (int k = 0; k < fl->nkinds && bl->kind < 0; k++)
            if (hash[rep[k]] == hash[b] && same_block(md, fl->F, &fl->blocks[rep[k]], bl))
                bl->kind = k;
        if (bl->kind >= 0)
            continue;
        bl->kind = fl->nkinds;
        rep[fl->nkinds++] = b;
    }
    /* each kind's tables, from its first block */
    for (int k = 0; k < fl->nkinds && !rc; k++) {
        const fl_block *bl = &fl->blocks[rep[k]];
        fl_kind *kd = &fl->kinds[k];
        kd->s = bl->s;
        kd->na = 2 * bl->s + 4; /* q, v and the forcing's 4 states */
        size_t nn = (size_t)kd->na * kd->na;
        double *A = malloc(nn * sizeof(double));
        kd->Minv = malloc((size_t)bl->s * bl->s * sizeof(double));
        kd->E = malloc((size_t)(fl->L + 2) * 2 * bl->s * kd->na * sizeof(double));
        if (!A || !kd->Minv || !kd->E)
            rc = pd_err_set(err, PD_ENOMEM,
                            "Moreau-Jean: out of memory for the tables of a "
                            "block of %d dofs",
                            bl->s);
        if (!rc && !(kd->Av = malloc((size_t)bl->s * kd->na * sizeof(double))))
            rc = pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for a block's tables");
        if (!rc && !(rc = augmented(md, fl, bl, kd, A, err))) {
            /* Av: A~'s v rows, the accelerations' map */
            for (int c = 0; c < kd->na; c++)
                for (int i = 0; i < bl->s; i++)
                    kd->Av[i + (size_t)c * bl->s] = A[bl->s + i + (size_t)c * kd->na];
            kd->wmax = block_wmax(kd, A);
            rc = ladder(fl, kd, A, err);
        }
        if (!rc)
            rc = impulse_responses(fl, kd, err);
        free(A);
    }
done:
    free(hash);
    free(rep);
    return rc;
}

/* ---- the object ------------------------------------------------------------------ */

void mj_flight_free(pd_mj *mj)
{
    mj_flight *fl = mj ? mj->fl : NULL;
    if (!fl)
        return;
    for (int k = 0; k < fl->nkinds && fl->kinds; k++) {
        free(fl->kinds[k].E);
        free(fl->kinds[k].Minv);
        free(fl->kinds[k].Av);
        free(fl->kinds[k].PV);
    }
    free(fl->kinds);
    free(fl->blocks);
    free(fl->block_of);
    free(fl->at);
    free(fl->dofs);
    free(fl->touched);
    free(fl->cmark);
    free(fl->pos);
    free(fl->rows);
    free(fl->vals);
    free(fl->r);
    free(fl->x);
    free(fl->h);
    free(fl->kind_d);
    free(fl->Ac);
    free(fl->zs);
    free(fl);
    mj->fl = NULL;
}

/* The forcing's one frequency: every sinusoidal piece's w (PD_EINVAL when
 * they differ). */
static int forcing_frequency(const pd_piecewise_force *F, double *w, pd_err *err)
{
    *w = 0.0;
    for (int p = 0; p < F->npieces; p++) {
        const pd_sine_piece *pc = &F->pieces[p];
        /* no sinusoid in this piece: any w */
        if (pc->A == 0.0)
            continue;
        if (*w != 0.0 && pc->w != *w)
            return pd_err_set(err, PD_EINVAL,
                              "Moreau-Jean: exact flights need one forcing "
                              "frequency (pieces %d: %g and earlier: %g)",
                              p, pc->w, *w);
        *w = pc->w;
    }
    return PD_OK;
}

/* Rows of SDOFs (every block one dof): each dof's kind, the kinds' maps of
 * a span and the forcing's states before its levels. */
static int sdof_tables(const pd_model *md, mj_flight *fl, pd_err *err)
{
    fl->sdofs = fl->nblocks == md->n;
    if (!fl->sdofs)
        return PD_OK;
    fl->kind_d = malloc((size_t)md->n * sizeof(int));
    fl->Ac = malloc((size_t)6 * fl->nkinds * sizeof(double));
    fl->zs = malloc((size_t)4 * (fl->L + 2) * sizeof(double));
    if (!fl->kind_d || !fl->Ac || !fl->zs)
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for its flights");
    for (int d = 0; d < md->n; d++)
        fl->kind_d[d] = fl->blocks[fl->block_of[d]].kind;
    return PD_OK;
}

int mj_flight_alloc(pd_mj *mj, const pd_piecewise_force *F, double h0, int L, pd_err *err)
{
    const pd_model *md = mj->model;
    int n = md->n, rc;
    mj_flight *fl = calloc(1, sizeof *fl);
    if (!(mj->fl = fl))
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for its flights");
    fl->F = F;
    fl->L = L;
    if ((rc = forcing_frequency(F, &fl->w, err)))
        return rc;
    fl->h = malloc((size_t)3 * (L + 2) * sizeof(double)); /* h, cm1, sw */
    fl->block_of = malloc((size_t)n * sizeof(int));
    fl->at = malloc((size_t)n * sizeof(int));
    fl->dofs = malloc((size_t)n * sizeof(int));
    fl->r = calloc((size_t)n, sizeof(double));
    fl->pos = pd_malloc(md->m, sizeof(int));
    fl->rows = pd_malloc(md->m, sizeof(int));
    fl->vals = pd_malloc(md->m, sizeof(double));
    if (!fl->h || !fl->block_of || !fl->at || !fl->dofs || !fl->r || !fl->pos || !fl->rows ||
        !fl->vals || find_blocks(md, fl) ||
        !(fl->touched = calloc((size_t)fl->nblocks, sizeof(unsigned))) ||
        !(fl->cmark = pd_calloc(md->m, sizeof(unsigned))))
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for its flights");
    fl->cm1 = fl->h + L + 2;
    fl->sw = fl->cm1 + L + 2;
    for (int k = 0; k <= L + 1; k++) {
        fl->h[k] = ldexp(h0, -k);
        /* cos(w h) - 1 = -2 sin^2(w h / 2): no cancellation at small w h */
        double half = sin(0.5 * fl->w * fl->h[k]);
        fl->cm1[k] = -2.0 * half * half;
        fl->sw[k] = sin(fl->w * fl->h[k]);
    }
    for (int a = 0; a < md->m; a++)
        fl->pos[a] = -1;
    /* x, dx and y: the largest block's augmented state, 2 smax + 4 each */
    int smax = 1;
    for (int b = 0; b < fl->nblocks; b++)
        smax = fl->blocks[b].s > smax ? fl->blocks[b].s : smax;
    if (!(fl->x = malloc((size_t)3 * (2 * smax + 4) * sizeof(double))))
        return pd_err_set(err, PD_ENOMEM, "Moreau-Jean: out of memory for its flights");
    fl->dx = fl->x + 2 * smax + 4;
    fl->y = fl->dx + 2 * smax + 4;
    if ((rc = form_kinds(md, fl, err)))
        return rc;
    return sdof_tables(md, fl, err);
}

void mj_flight_z(const pd_mj *mj, int p, double t, double *z)
{
    const pd_sine_piece *pc = &mj->fl->F->pieces[p];
    /* z = [A sin(w t + phi), A cos(w t + phi), c0 + c1 (t - ts), c1] */
    double ph = pc->w * t + pc->phi;
    z[0] = pc->A * sin(ph);
    z[1] = pc->A * cos(ph);
    z[2] = pc->c0 + pc->c1 * (t - pc->t_start);
    z[3] = pc->c1;
}

double mj_flight_forcing_w(const pd_mj *mj)
{
    return mj->fl->w;
}

double mj_flight_wmax(const pd_mj *mj, int dof)
{
    const mj_flight *fl = mj->fl;
    /* the larger of the block's bound and the forcing's frequency */
    return fmax(fl->kinds[fl->blocks[fl->block_of[dof]].kind].wmax, fl->w);
}

/* ---- a step -------------------------------------------------------------------------- */

/* The free flight of block bl over level k: out's q, v from in's and z. */
static void free_flight(const mj_flight *fl, const fl_block *bl, int k, const pd_state *in,
                        const double *z, pd_state *out)
{
    const fl_kind *kd = &fl->kinds[bl->kind];
    const double *E = level_E(kd, k);
    int s = bl->s, rows = 2 * s, na = kd->na;
    double *x = fl->x, *dx = fl->dx;
    if (s == 1) { /* an SDOF: rows q and v of E by columns q, v, z0..z3 */
        int d = bl->dofs[0];
        double q = in->q[d], v = in->v[d];
        double dq = E[0] * q + E[2] * v + E[4] * z[0] + E[6] * z[1] + E[8] * z[2] + E[10] * z[3];
        double dv = E[1] * q + E[3] * v + E[5] * z[0] + E[7] * z[1] + E[9] * z[2] + E[11] * z[3];
        out->q[d] = q + dq;
        out->v[d] = v + dv;
        return;
    }
    for (int i = 0; i < s; i++) {
        /* x = [q; v; z] of the block, dx = E_k x (its first 2 s rows) */
        x[i] = in->q[bl->dofs[i]];
        x[s + i] = in->v[bl->dofs[i]];
    }
    for (int i = 0; i < 4; i++)
        x[rows + i] = z[i];
    for (int r = 0; r < rows; r++)
        dx[r] = 0.0;
    for (int c = 0; c < na; c++) {
        double xc = x[c];
        if (xc == 0.0) /* adds nothing: at rest, a zero of z */
            continue;
        for (int r = 0; r < rows; r++)
            dx[r] += E[r + (size_t)c * rows] * xc;
    }
    for (int i = 0; i < s; i++) {
        /* x+ = x + E_k x: the increment keeps tiny steps exact */
        out->q[bl->dofs[i]] = x[i] + dx[i];
        out->v[bl->dofs[i]] = x[s + i] + dx[s + i];
    }
}

/* D_ab = W_a^T Phi_vv(h/2) M^-1 W_b over the blocks they share (PV_k), or,
 * given minv (M diagonal), W_a^T M^-1 W_b = sum_i W_ia W_ib / M_ii. */
static double delassus(const pd_mj *mj, int k, const double *minv, int a, int b)
{
    const mj_flight *fl = mj->fl;
    const mj_incidence *in = &mj->inc;
    double sum = 0.0;
    for (int p = in->ptr[a]; p < in->ptr[a + 1]; p++) {
        int i = in->dof[p], bi = fl->block_of[i];
        const fl_block *bl = &fl->blocks[bi];
        const fl_kind *kd = &fl->kinds[bl->kind];
        int s = bl->s;
        const double *PV = kd->PV + (size_t)k * s * s;
        for (int q = in->ptr[b]; q < in->ptr[b + 1]; q++) {
            int j = in->dof[q];
            /* PV is block diagonal: W_ia PV_ij W_jb for i, j in one block */
            if (minv)
                sum += i == j ? in->w[p] * minv[i] * in->w[q] : 0.0;
            else if (fl->block_of[j] == bi)
                sum += in->w[p] * PV[fl->at[i] + (size_t)fl->at[j] * s] * in->w[q];
        }
    }
    return sum;
}

/* Sort v[0..n) increasing, x (NULL: none) along (a column's few rows:
 * insertion). */
static void sort_rows(int *v, double *x, int n)
{
    for (int i = 1; i < n; i++) {
        int vi = v[i], j = i;
        double xi = x ? x[i] : 0.0;
        for (; j > 0 && v[j - 1] > vi; j--) {
            v[j] = v[j - 1];
            if (x)
                x[j] = x[j - 1];
        }
        v[j] = vi;
        if (x)
            x[j] = xi;
    }
}

/* Rows of SDOFs: column a of D in one pass over its dofs, D_ba = sum over
 * their shared dofs i of W_ib P_i W_ia (P_i = PV_k of its kind, or minv_i),
 * delassus's terms in its order; rows and values, unsorted, into rows and
 * vals: their number. */
static int sdof_column(const pd_mj *mj, int k, const double *minv, int a, int *rows, double *vals)
{
    const mj_flight *fl = mj->fl;
    const mj_incidence *in = &mj->inc;
    int nr = 0;
    for (int p = in->ptr[a]; p < in->ptr[a + 1]; p++) {
        int i = in->dof[p];
        double Pi = minv ? minv[i] : fl->kinds[fl->kind_d[i]].PV[k];
        for (int q = in->dptr[i]; q < in->dptr[i + 1]; q++) {
            int r = fl->pos[in->con[q]], e = 0;
            if (r < 0) /* not active */
                continue;
            double t = in->wr[q] * Pi * in->w[p];
            while (e < nr && rows[e] != r)
                e++;
            if (e == nr) {
                rows[nr] = r;
                vals[nr++] = t;
            } else {
                vals[e] += t;
            }
        }
    }
    return nr;
}

/* The rows of the active contacts on the blocks contact a touches (the
 * nonzeros of its column of D), each once (stamps), into rows: their number. */
static int column_rows(pd_mj *mj, int a, int *rows)
{
    mj_flight *fl = mj->fl;
    const mj_incidence *in = &mj->inc;
    unsigned stamp = ++fl->stamp;
    int nr = 0;
    for (int p = in->ptr[a]; p < in->ptr[a + 1]; p++) {
        int bi = fl->block_of[in->dof[p]];
        if (fl->touched[bi] == stamp)
            continue;
        fl->touched[bi] = stamp;
        const fl_block *bl = &fl->blocks[bi];
        for (int d = 0; d < bl->s; d++) {
            int i = bl->dofs[d];
            for (int q = in->dptr[i]; q < in->dptr[i + 1]; q++) {
                int b = in->con[q];
                if (fl->pos[b] < 0 || fl->cmark[b] == stamp)
                    continue;
                fl->cmark[b] = stamp;
                rows[nr++] = fl->pos[b];
            }
        }
    }
    return nr;
}

/* D_II of the active set into mj->D_active (delassus: at level k, or with
 * M^-1 = diag(minv)): dense, or compressed columns with the contacts that
 * share a block (found through the dofs of each block a contact acts on;
 * rows of SDOFs: sdof_column). */
void mj_flight_delassus(pd_mj *mj, int k, const double *minv, int nI)
{
    mj_flight *fl = mj->fl;
    for (int r = 0; r < nI; r++)
        fl->pos[mj->idx_active[r]] = r; /* each active contact's row */
    if (!mj->sparse) {
        /* D_rc = 0 unless r and c share a block */
        for (int c = 0; c < nI; c++) {
            int a = mj->idx_active[c];
            double *col = mj->D_active + (size_t)c * nI;
            for (int r = 0; r < nI; r++)
                col[r] = 0.0;
            if (fl->sdofs) {
                for (int e = 0, nr = sdof_column(mj, k, minv, a, fl->rows, fl->vals); e < nr; e++)
                    col[fl->rows[e]] = fl->vals[e];
                continue;
            }
            for (int e = 0, nr = column_rows(mj, a, fl->rows); e < nr; e++)
                col[fl->rows[e]] = delassus(mj, k, minv, mj->idx_active[fl->rows[e]], a);
        }
    } else {
        int nnz = 0;
        for (int c = 0; c < nI; c++) {
            int a = mj->idx_active[c], start = nnz;
            mj->D_colptr[c] = nnz;
            if (fl->sdofs) {
                nnz += sdof_column(mj, k, minv, a, mj->D_rowind + start, mj->D_active + start);
                /* rows increasing, as compressed columns have them */
                sort_rows(mj->D_rowind + start, mj->D_active + start, nnz - start);
                continue;
            }
            nnz += column_rows(mj, a, mj->D_rowind + start);
            sort_rows(mj->D_rowind + start, NULL, nnz - start);
            for (int e = start; e < nnz; e++)
                mj->D_active[e] = delassus(mj, k, minv, mj->idx_active[mj->D_rowind[e]], a);
        }
        mj->D_colptr[nI] = nnz;
    }
    for (int r = 0; r < nI; r++)
        fl->pos[mj->idx_active[r]] = -1; /* clean for the next step */
}

/* The impulses' response at mid-step: v += Phi_vv(h/2) M^-1 W P, q +=
 * Phi_qv(h/2) M^-1 W P on the blocks the active contacts act on. */
static void apply_impulses(pd_mj *mj, int k, int nI, pd_state *out)
{
    mj_flight *fl = mj->fl;
    const mj_incidence *in = &mj->inc;
    fl->stamp++;                   /* each block once */
    for (int c = 0; c < nI; c++) { /* r = W P on the dofs */
        int a = mj->idx_active[c];
        for (int p = in->ptr[a]; p < in->ptr[a + 1]; p++)
            fl->r[in->dof[p]] += in->w[p] * mj->P_active[c];
    }
    for (int c = 0; c < nI; c++) {
        int a = mj->idx_active[c];
        for (int p = in->ptr[a]; p < in->ptr[a + 1]; p++) {
            int bi = fl->block_of[in->dof[p]];
            if (fl->touched[bi] == fl->stamp)
                continue;
            fl->touched[bi] = fl->stamp;
            const fl_block *bl = &fl->blocks[bi];
            const fl_kind *kd = &fl->kinds[bl->kind];
            int s = bl->s;
            /* q += PQ_k r, v += PV_k r on the block, then r back to 0 */
            const double *PV = kd->PV + (size_t)k * s * s, *PQ = kd->PQ + (size_t)k * s * s;
            for (int i = 0; i < s; i++) {
                double dq = 0.0, dv = 0.0;
                for (int l = 0; l < s; l++) {
                    double rl = fl->r[bl->dofs[l]];
                    dq += PQ[i + (size_t)l * s] * rl;
                    dv += PV[i + (size_t)l * s] * rl;
                }
                out->q[bl->dofs[i]] += dq;
                out->v[bl->dofs[i]] += dv;
            }
            for (int i = 0; i < s; i++)
                fl->r[bl->dofs[i]] = 0.0;
        }
    }
}

/* Contacts held through the step (shut at its start and pushing) keep
 * their gap inside the step: the impulses hold their gap rate at zero, the
 * gap itself drifts by O(h^3) per step (the force varies inside the step),
 * a drift the halves and the whole step would differ by; q moves along
 * M^-1 W_a to put it back (Gauss-Seidel sweeps over held contacts that
 * share a dof; M^-1 by its diagonal).  The kept states are put on the
 * contacts again (mj_adapt.c, hold_gaps). */
#define FL_HOLD_SWEEPS 3
static void hold_gaps(pd_mj *mj, int nI, const pd_state *in, pd_state *out)
{
    const pd_model *md = mj->model;
    const mj_incidence *inc = &mj->inc;
    for (int sweep = 0; sweep < FL_HOLD_SWEEPS; sweep++)
        for (int r = 0; r < nI; r++) {
            int a = mj->idx_active[r];
            /* held: pushing, and shut at the start */
            if (!(out->P[a] > 0.0) || in->g[a] > 0.0)
                continue;
            /* d: back to the gap at the step's start */
            double g = md->g0[a] + mj_inc_dot(inc, a, out->q), d = in->g[a] - g;
            if (d == 0.0 || !(mj->D0[a] > 0.0))
                continue;
            /* q += M^-1 W_a d / D0_a moves the gap by d (M^-1 by its diagonal) */
            for (int j = inc->ptr[a]; j < inc->ptr[a + 1]; j++)
                out->q[inc->dof[j]] += mj->minv[inc->dof[j]] * inc->w[j] * d / mj->D0[a];
        }
}

void mj_flight_acc(const pd_mj *mj, const pd_state *st, const double *z, double *acc)
{
    const mj_flight *fl = mj->fl;
    if (fl->sdofs) { /* rows of SDOFs: the sums below with s = 1 */
        for (int d = 0; d < mj->model->n; d++) {
            const double *Av = fl->kinds[fl->kind_d[d]].Av;
            double sum = 0.0;
            sum += Av[0] * st->q[d] + Av[1] * st->v[d];
            /* f = z0 + z2: z1 and z3 (Av[3], Av[5] = 0) add nothing */
            sum += Av[2] * z[0];
            sum += Av[4] * z[2];
            acc[d] = sum;
        }
        return;
    }
    for (int b = 0; b < fl->nblocks; b++) {
        const fl_block *bl = &fl->blocks[b];
        const fl_kind *kd = &fl->kinds[bl->kind];
        int s = bl->s;
        for (int i = 0; i < s; i++) {
            double sum = 0.0;
            for (int l = 0; l < s; l++)
                sum += kd->Av[i + (size_t)l * s] * st->q[bl->dofs[l]] +
                       kd->Av[i + (size_t)(s + l) * s] * st->v[bl->dofs[l]];
            for (int c = 0; c < 4; c++)
                sum += kd->Av[i + (size_t)(2 * s + c) * s] * z[c];
            /* a = Av [q; v; z] = -M^-1 (K q + C v) + M^-1 b f */
            acc[bl->dofs[i]] = sum;
        }
    }
}

/* z over level k (zout may be zin): the sinusoid turned by w h, (z0, z1)
 * += (cos - 1) (z0, z1) + sin (z1, -z0); the line advanced. */
static void z_turn(const mj_flight *fl, int k, const double *zin, double *zout)
{
    double z0 = zin[0], z1 = zin[1], z2 = zin[2], z3 = zin[3];
    zout[0] = z0 + fl->cm1[k] * z0 + fl->sw[k] * z1;
    zout[1] = z1 + fl->cm1[k] * z1 - fl->sw[k] * z0;
    zout[2] = z2 + fl->h[k] * z3;
    zout[3] = z3;
}

/* An SDOF kind's flight over levels lev[0..nlev) from the forcing's states
 * zs (before each level) as one map x -> x + A x + c (A 2 x 2 by columns,
 * then c, into Ac): level j's E = [Ex | Ez] takes x_j = (I + A_j) x_0 + c_j
 * to x_j + Ex x_j + Ez z_j, so A_j+1 = A_j + Ex (I + A_j) and c_j+1 = c_j +
 * Ex c_j + Ez z_j (increments: tiny steps stay exact). */
static void sdof_compose(const double *E0, const int *lev, int nlev, const double *zs, double *Ac)
{
    double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0, c0 = 0.0, c1 = 0.0;
    for (int j = 0; j < nlev; j++) {
        const double *E = E0 + (size_t)lev[j] * 12, *z = zs + 4 * j;
        double fz0 = E[4] * z[0] + E[6] * z[1] + E[8] * z[2] + E[10] * z[3];
        double fz1 = E[5] * z[0] + E[7] * z[1] + E[9] * z[2] + E[11] * z[3];
        /* Ex (I + A): columns (1 + a0, a1) and (a2, 1 + a3) */
        double b0 = E[0] * (1.0 + a0) + E[2] * a1, b1 = E[1] * (1.0 + a0) + E[3] * a1;
        double b2 = E[0] * a2 + E[2] * (1.0 + a3), b3 = E[1] * a2 + E[3] * (1.0 + a3);
        double d0 = E[0] * c0 + E[2] * c1 + fz0, d1 = E[1] * c0 + E[3] * c1 + fz1;
        a0 += b0;
        a1 += b1;
        a2 += b2;
        a3 += b3;
        c0 += d0;
        c1 += d1;
    }
    Ac[0] = a0;
    Ac[1] = a1;
    Ac[2] = a2;
    Ac[3] = a3;
    Ac[4] = c0;
    Ac[5] = c1;
}

/* The free flights of levels lev[0..nlev) in turn from in into out (no
 * contact): every block's, z turned by w h and its line advanced. */
static void free_flights(const mj_flight *fl, const int *lev, int nlev, const pd_state *in,
                         const double *zin, pd_state *out, double *zout)
{
    if (fl->sdofs) { /* rows of SDOFs: each kind's flight over the levels, then each dof */
        double *zs = fl->zs;
        for (int i = 0; i < 4; i++)
            zs[i] = zin[i];
        for (int j = 0; j < nlev; j++)
            z_turn(fl, lev[j], zs + 4 * j, zs + 4 * (j + 1));
        for (int c = 0; c < fl->nkinds; c++)
            sdof_compose(fl->kinds[c].E, lev, nlev, zs, fl->Ac + 6 * c);
        for (int d = 0; d < fl->nblocks; d++) {
            const double *A = fl->Ac + 6 * fl->kind_d[d];
            double q = in->q[d], v = in->v[d];
            out->q[d] = q + (A[0] * q + A[2] * v + A[4]);
            out->v[d] = v + (A[1] * q + A[3] * v + A[5]);
        }
        for (int i = 0; i < 4; i++)
            zout[i] = zs[4 * nlev + i];
        return;
    }
    for (int j = 0; j < nlev; j++) {
        int k = lev[j];
        for (int b = 0; b < fl->nblocks; b++)
            free_flight(fl, &fl->blocks[b], k, j ? out : in, j ? zout : zin, out);
        z_turn(fl, k, zin, zout);
        zin = zout;
    }
}

/* The contacts shut at the start (within sim_gap) or at the free flight's
 * end, but for those the free flight opens, into mj->idx_active (their
 * guesses too), their U_k into mj->U0 (from in: out is another state);
 * every gap at the end into out.  Returns their number. */
static int shut_contacts(pd_mj *mj, const pd_state *in, pd_state *out)
{
    const pd_model *md = mj->model;
    int nI = 0;
    for (int a = 0; a < md->m; a++) {
        double g_start = in->g[a], g_end = md->g0[a] + mj_inc_dot(&mj->inc, a, out->q);
        out->active[a] = 0;
        out->P[a] = 0.0;
        out->g[a] = g_end;
        if (!(g_start <= mj->opts.sim_gap || g_end <= 0.0))
            continue;
        /* U_k of a shut contact (the impacts' restitution) */
        mj->U0[a] = mj_inc_dot(&mj->inc, a, in->v);
        /* an opening contact (faster than u_rest) left open by the free flight
         * takes no impulse: if an impulse of this step makes it close, the
         * next step's is its own impact (the references' next stage) */
        /* opening: U_k above its rest speed, and the free flight did not close it */
        int opening = mj->U0[a] > mj->u_rest[a] && g_end >= g_start;
        if (!opening) {
            unsigned char was = in->active[a] ? in->P[a] > 0.0 : 2;
            out->active[a] = 1;
            if (mj->guess)
                mj->guess[nI] = was;
            mj->idx_active[nI++] = a;
        }
    }
    out->nactive = nI;
    return nI;
}

/* The state's dofs finite, or PD_ENONFINITE. */
static int check_finite(const pd_mj *mj, double t1, const pd_state *out, pd_err *err)
{
    for (int i = 0; i < mj->model->n; i++)
        if (!isfinite(out->q[i]) || !isfinite(out->v[i]))
            return pd_err_set(err, PD_ENONFINITE,
                              "Moreau-Jean: non-finite state at t = %.9g (dof %d)", t1, i);
    return PD_OK;
}

/* The free flights of levels lev[0..nlev) from in into out (another
 * state) ending at t1, the contacts they shut (shut_contacts): their
 * number. */
static int fly(pd_mj *mj, const int *lev, int nlev, double t1, const pd_state *in,
               const double *zin, pd_state *out, double *zout)
{
    free_flights(mj->fl, lev, nlev, in, zin, out, zout);
    out->t = t1;
    out->step = in->step + 1;
    out->lcp_pivots = 0;
    out->lcp_solver = NULL;
    return shut_contacts(mj, in, out);
}

int mj_flight_span(pd_mj *mj, const int *lev, int nlev, double t1, const pd_state *in,
                   const double *zin, pd_state *out, double *zout, pd_err *err)
{
    if (fly(mj, lev, nlev, t1, in, zin, out, zout) > 0)
        return 0;
    int rc = check_finite(mj, t1, out, err);
    return rc ? rc : 1;
}

int mj_flight_step(pd_mj *mj, int k, double t1, const pd_state *in, const double *zin,
                   pd_state *out, double *zout, pd_err *err)
{
    const pd_model *md = mj->model;
    int rc, nI = fly(mj, &k, 1, t1, in, zin, out, zout);
    if (nI > 0) {
        /* D = W_I^T Phi_vv(h/2) M^-1 W_I and b = W_I^T v_free + e U_k; the impulses at mid-step */
        mj_flight_delassus(mj, k, NULL, nI);
        mj_active_rhs(mj, nI, out->v);
        if ((rc = mj_impact_active(mj, nI, t1, out, err)))
            return rc;
        apply_impulses(mj, k, nI, out);
        hold_gaps(mj, nI, in, out);
        /* the impulses and the holds moved the dofs of the active contacts,
         * which other contacts share: every gap anew */
        for (int a = 0; a < md->m; a++)
            out->g[a] = md->g0[a] + mj_inc_dot(&mj->inc, a, out->q);
    }
    return check_finite(mj, t1, out, err);
}
