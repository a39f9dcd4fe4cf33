/* scene.c — rows of structures (SPEC §4): building a scene, checking it,
 * its periods and damping, and the engine model it gives.
 *
 * A shear building of s storeys: masses m_i, storey stiffnesses k_i (k_1
 * joins storey 1 to the ground), K tridiagonal with K_ii = k_i + k_i+1,
 * K_i,i+1 = -k_i+1.  Periods from the tridiagonal eigenproblem
 * M^-1/2 K M^-1/2 by Sturm bisection.  Classical damping C = alpha M + beta K:
 * Rayleigh through xi at modes i, j (alpha = 2 xi wi wj / (wi + wj),
 * beta = 2 xi / (wi + wj)), or stiffness-proportional through xi at mode 1;
 * an SDOF gets c = 2 xi w0 m exactly. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_alloc.h"
#include "pd_problems.h"
#include "pd_null.h"
#include "scene_priv.h"

#define SCENE_MAX_STOREYS 100000

pd_scene *pd_scene_new(const pd_scene_excitation *exc)
{
    pd_scene *sc = calloc(1, sizeof *sc);
    if (sc && exc)
        sc->exc = *exc;
    return sc;
}

void pd_scene_free(pd_scene *sc)
{
    if (!sc)
        return;
    for (int s = 0; s < sc->nstruct; s++) {
        free(sc->st[s].mass);
        free(sc->st[s].stiffness);
        free(sc->st[s].height);
        free(sc->st[s].uy);
        free(sc->st[s].yield_alpha);
    }
    free(sc->st);
    free(sc->ct);
    free(sc->names);
    if (sc->own_record) {
        pd_record_free(sc->own_record);
        free(sc->own_record);
    }
    free(sc);
}

pd_scene *pd_scene_copy(const pd_scene *sc)
{
    if (!sc)
        return NULL;
    pd_scene *c = pd_scene_new(&sc->exc);
    int ok = c != NULL;
    for (int s = 0; ok && s < sc->nstruct; s++) {
        const pd_structure *st = &sc->st[s];
        ok = pd_scene_add_building(c, st->name, st->storeys, st->mass, st->stiffness, st->xi,
                                   NULL) == PD_OK;
        if (ok)
            c->st[s] = (pd_structure){.storeys = st->storeys,
                                      .mass = c->st[s].mass,
                                      .stiffness = c->st[s].stiffness,
                                      .height = c->st[s].height,
                                      .xi = st->xi,
                                      .damping = st->damping,
                                      .modes = {st->modes[0], st->modes[1]}};
        if (ok) {
            memcpy(c->st[s].name, st->name, sizeof st->name);
            if (st->height)
                memcpy(c->st[s].height, st->height, (size_t)st->storeys * sizeof(double));
            if (st->uy) /* the yielding storeys */
                ok = pd_scene_set_yield(c, st->uy, st->yield_alpha, NULL) == PD_OK;
        }
    }
    for (int a = 0; ok && a < sc->ncontact; a++) {
        const pd_contact *ct = &sc->ct[a];
        ok = pd_scene_add_contact(c, ct->a, ct->level_a, ct->b, ct->level_b, ct->gap, ct->eps,
                                  ct->entry, NULL) == PD_OK;
    }
    if (!ok) {
        pd_scene_free(c);
        return NULL;
    }
    c->tend = sc->tend;
    return c;
}

/* FNV-1a hash of a name. */
static unsigned name_hash(const char *name)
{
    unsigned h = 2166136261u;
    for (const unsigned char *c = (const unsigned char *)name; *c; c++)
        h = (h ^ *c) * 16777619u;
    return h;
}

/* The slot of name in the table: its structure's, or the empty one it
 * would take (the table is never full). */
static int name_slot(const pd_scene *sc, const char *name)
{
    unsigned mask = (unsigned)sc->name_cap - 1u, k = name_hash(name) & mask;
    while (sc->names[k] && strcmp(sc->st[sc->names[k] - 1].name, name))
        k = (k + 1u) & mask;
    return (int)k;
}

/* Room in the name table for one more structure, at most half full:
 * rebuilt twice as large when needed.  PD_OK or PD_ENOMEM. */
static int names_grow(pd_scene *sc)
{
    if (2 * (sc->nstruct + 1) <= sc->name_cap)
        return PD_OK;
    int cap = sc->name_cap ? 2 * sc->name_cap : 64, *old = sc->names;
    if (!(sc->names = calloc((size_t)cap, sizeof(int)))) {
        sc->names = old;
        return PD_ENOMEM;
    }
    free(old);
    sc->name_cap = cap;
    for (int s = 0; s < sc->nstruct; s++)
        sc->names[name_slot(sc, sc->st[s].name)] = s + 1;
    return PD_OK;
}

int pd_scene_find(const pd_scene *sc, const char *name)
{
    if (!sc || !name)
        return -2;
    if (!strcmp(name, "wall"))
        return PD_WALL;
    if (sc->name_cap == 0)
        return -2;
    int k = sc->names[name_slot(sc, name)];
    return k ? k - 1 : -2;
}

/* Room for one more structure (with its storey arrays) or contact. */
static int grow(void **arr, int *cap, int need, size_t size)
{
    if (need <= *cap)
        return PD_OK;
    int ncap = *cap ? 2 * *cap : 8;
    while (ncap < need)
        ncap *= 2;
    void *p = realloc(*arr, (size_t)ncap * size);
    if (!p)
        return PD_ENOMEM;
    *arr = p;
    *cap = ncap;
    return PD_OK;
}

/* A new structure: name checked, storey arrays allocated. */
static pd_structure *new_structure(pd_scene *sc, const char *name, int storeys, double xi,
                                   pd_err *err)
{
    if (!name || !name[0] || strlen(name) >= PD_NAME_MAX) {
        pd_err_set(err, PD_EINVAL, "name: must be 1 to %d characters", PD_NAME_MAX - 1);
        return NULL;
    }
    /* names head CSV columns (NAME.x1), HDF5 groups (/structures/NAME) and
     * JSON strings: nothing those read as syntax */
    for (const char *c = name; *c; c++)
        if ((unsigned char)*c < 0x20 || *c == 0x7f || strchr("/\\,\"'", *c)) {
            pd_err_set(err, PD_EINVAL,
                       "name: may not contain %s (it heads CSV columns and "
                       "HDF5 groups)",
                       (unsigned char)*c < 0x20 || *c == 0x7f ? "control characters"
                       : *c == ','                            ? "','"
                       : *c == '/'                            ? "'/'"
                       : *c == '\\'                           ? "'\\'"
                                                              : "quotes");
            return NULL;
        }
    if (!strcmp(name, ".") || !strcmp(name, "..") || name[0] == ' ' ||
        name[strlen(name) - 1] == ' ') {
        pd_err_set(err, PD_EINVAL,
                   "name: '%s' is not a usable name (not '.' or '..', no space "
                   "at either end)",
                   name);
        return NULL;
    }
    if (pd_scene_find(sc, name) != -2) {
        pd_err_set(err, PD_EINVAL, "name: '%s' %s", name,
                   strcmp(name, "wall") ? "is used twice" : "is reserved for the walls");
        return NULL;
    }
    if (storeys < 1 || storeys > SCENE_MAX_STOREYS) {
        pd_err_set(err, PD_EINVAL, "storeys: must be an integer in [1, %d] (got %d)",
                   SCENE_MAX_STOREYS, storeys);
        return NULL;
    }
    if (!(xi >= 0.0 && xi < 1.0)) {
        pd_err_set(err, PD_EINVAL, "xi: the damping ratio must be in [0, 1) (got %g)", xi);
        return NULL;
    }
    if (grow((void **)&sc->st, &sc->cap_struct, sc->nstruct + 1, sizeof *sc->st) ||
        names_grow(sc)) {
        pd_err_set(err, PD_ENOMEM, "out of memory for structure '%s'", name);
        return NULL;
    }
    pd_structure *st = &sc->st[sc->nstruct];
    memset(st, 0, sizeof *st);
    st->mass = malloc((size_t)storeys * sizeof(double));
    st->stiffness = malloc((size_t)storeys * sizeof(double));
    st->height = malloc((size_t)storeys * sizeof(double));
    if (!st->mass || !st->stiffness || !st->height) {
        free(st->mass);
        free(st->stiffness);
        free(st->height);
        pd_err_set(err, PD_ENOMEM, "out of memory for structure '%s'", name);
        return NULL;
    }
    snprintf(st->name, sizeof st->name, "%s", name);
    for (int i = 0; i < storeys; i++)
        st->height[i] = PD_STOREY_HEIGHT;
    st->storeys = storeys;
    st->xi = xi;
    st->damping = PD_DAMPING_RAYLEIGH;
    st->modes[0] = 1;
    st->modes[1] = 2;
    sc->names[name_slot(sc, st->name)] = sc->nstruct + 1;
    sc->nstruct++;
    sc->finished = 0;
    return st;
}

/* A finite value > 0. */
static int positive(double x)
{
    return x > 0.0 && isfinite(x);
}

/* The stiffness k derived from T0 and mass: a normal double > 0 (a period
 * of 1e-300 s makes m (2 pi / T0)^2 infinite, one of 1e300 s makes it 0). */
static int derived_stiffness(double k, double T0, double mass, pd_err *err)
{
    if (isnormal(k) && k > 0.0)
        return PD_OK;
    return pd_err_set(err, PD_EINVAL,
                      "T0: a period of %g s with a mass of %g kg gives a "
                      "stiffness of %g N/m, not a usable number",
                      T0, mass, k);
}

int pd_scene_add_sdof(pd_scene *sc, const char *name, double T0, double xi, double mass,
                      pd_err *err)
{
    pd_err own_err; /* the status read back when the caller passed no pd_err */
    err = pd_err_or(err, &own_err);
    if (!sc || !name)
        return PD_NULL_ARG(err, !sc ? "sc" : "name");
    if (!positive(T0))
        return pd_err_set(err, PD_EINVAL, "T0: the period must be > 0 (got %g)", T0);
    if (!positive(mass))
        return pd_err_set(err, PD_EINVAL, "mass: must be > 0 (got %g)", mass);
    double w0 = PD_TWO_PI / T0, k = mass * w0 * w0;
    int rc = derived_stiffness(k, T0, mass, err);
    pd_structure *st = rc ? NULL : new_structure(sc, name, 1, xi, err);
    if (!st)
        return rc ? rc : err->status;
    st->mass[0] = mass;
    st->stiffness[0] = k;
    return PD_OK;
}

int pd_scene_add_building(pd_scene *sc, const char *name, int storeys, const double *masses,
                          const double *stiffnesses, double xi, pd_err *err)
{
    pd_err own_err; /* the status read back when the caller passed no pd_err */
    err = pd_err_or(err, &own_err);
    if (!sc || !name || !masses || !stiffnesses)
        return PD_NULL_ARG(err, !sc ? "sc" : !name ? "name" : !masses ? "masses" : "stiffnesses");
    for (int i = 0; i < storeys && storeys <= SCENE_MAX_STOREYS; i++) {
        if (!positive(masses[i]))
            return pd_err_set(err, PD_EINVAL, "masses: storey %d has mass %g, must be > 0", i + 1,
                              masses[i]);
        if (!positive(stiffnesses[i]))
            return pd_err_set(err, PD_EINVAL,
                              "stiffnesses: storey %d has stiffness %g, must be > 0", i + 1,
                              stiffnesses[i]);
    }
    pd_structure *st = new_structure(sc, name, storeys, xi, err);
    if (!st)
        return err->status;
    memcpy(st->mass, masses, (size_t)storeys * sizeof(double));
    memcpy(st->stiffness, stiffnesses, (size_t)storeys * sizeof(double));
    return PD_OK;
}

/* Uniform shear building: w1 = 2 sqrt(k/m) sin(pi / (2 (2 s + 1))). */
int pd_scene_add_uniform(pd_scene *sc, const char *name, int storeys, double mass, double T0,
                         double xi, pd_err *err)
{
    pd_err own_err; /* the status read back when the caller passed no pd_err */
    err = pd_err_or(err, &own_err);
    if (!sc || !name)
        return PD_NULL_ARG(err, !sc ? "sc" : "name");
    if (!positive(T0))
        return pd_err_set(err, PD_EINVAL, "T0: the period must be > 0 (got %g)", T0);
    if (!positive(mass))
        return pd_err_set(err, PD_EINVAL, "mass: must be > 0 (got %g)", mass);
    double w1 = PD_TWO_PI / T0, s = sin(PD_PI / (2.0 * (2.0 * storeys + 1.0)));
    double k = mass * w1 * w1 / (4.0 * s * s);
    int rc = derived_stiffness(k, T0, mass, err);
    pd_structure *st = rc ? NULL : new_structure(sc, name, storeys, xi, err);
    if (!st)
        return rc ? rc : err->status;
    for (int i = 0; i < storeys; i++) {
        st->mass[i] = mass;
        st->stiffness[i] = k;
    }
    return PD_OK;
}

int pd_scene_set_damping(pd_scene *sc, pd_damping damping, int mode1, int mode2, pd_err *err)
{
    if (!sc)
        return PD_NULL_ARG(err, "sc");
    if (sc->nstruct == 0)
        return pd_err_set(err, PD_EINVAL, "damping: no structure to apply it to");
    pd_structure *st = &sc->st[sc->nstruct - 1];
    if (damping != PD_DAMPING_RAYLEIGH && damping != PD_DAMPING_STIFFNESS)
        return pd_err_set(err, PD_EINVAL, "damping: unknown model %d", (int)damping);
    if (damping == PD_DAMPING_RAYLEIGH && st->storeys > 1 &&
        !(mode1 >= 1 && mode2 > mode1 && mode2 <= st->storeys))
        return pd_err_set(err, PD_EINVAL,
                          "rayleigh_modes: need two modes 1 <= i < j <= %d (got %d, %d)",
                          st->storeys, mode1, mode2);
    st->damping = damping;
    st->modes[0] = mode1;
    st->modes[1] = mode2;
    sc->finished = 0;
    return PD_OK;
}

int pd_scene_set_heights(pd_scene *sc, const double *heights, pd_err *err)
{
    if (!sc || !heights)
        return PD_NULL_ARG(err, !sc ? "sc" : "heights");
    if (sc->nstruct == 0)
        return pd_err_set(err, PD_EINVAL, "storey_heights: no structure to apply them to");
    pd_structure *st = &sc->st[sc->nstruct - 1];
    for (int i = 0; i < st->storeys; i++)
        if (!positive(heights[i]))
            return pd_err_set(err, PD_EINVAL,
                              "storey_heights: storey %d has height %g, must be a finite "
                              "number > 0 [m]",
                              i + 1, heights[i]);
    memcpy(st->height, heights, (size_t)st->storeys * sizeof(double));
    return PD_OK;
}

/* Structure st's yielding storeys: uy[i] > 0 (INFINITY: elastic), alpha[i]
 * in [0, 1] (alpha NULL: 0), or alpha_all for every storey when alpha_all
 * >= 0 and uy_all for every storey when uy is NULL. */
static int structure_yield(pd_structure *st, const double *uy, double uy_all, const double *alpha,
                           double alpha_all, pd_err *err)
{
    for (int i = 0; i < st->storeys; i++) {
        double u = uy ? uy[i] : uy_all, a = alpha ? alpha[i] : alpha_all;
        if (!(u > 0.0)) /* INFINITY passes: an elastic storey */
            return pd_err_set(err, PD_EINVAL,
                              "uy: storey %d has yield drift %g, must be > 0 [m] (inf: elastic)",
                              i + 1, u);
        if (!(a >= 0.0 && a <= 1.0))
            return pd_err_set(err, PD_EINVAL,
                              "alpha: storey %d has post-yield stiffness ratio %g, must be in "
                              "[0, 1]",
                              i + 1, a);
    }
    size_t bytes = (size_t)st->storeys * sizeof(double);
    if (!st->uy && (!(st->uy = malloc(bytes)) || !(st->yield_alpha = malloc(bytes)))) {
        free(st->uy);
        st->uy = NULL;
        return pd_err_set(err, PD_ENOMEM, "out of memory for the yield drifts of '%s'", st->name);
    }
    for (int i = 0; i < st->storeys; i++) {
        st->uy[i] = uy ? uy[i] : uy_all;
        st->yield_alpha[i] = alpha ? alpha[i] : alpha_all;
    }
    return PD_OK;
}

int pd_scene_set_yield(pd_scene *sc, const double *uy, const double *alpha, pd_err *err)
{
    if (!sc || !uy)
        return PD_NULL_ARG(err, !sc ? "sc" : "uy");
    if (sc->nstruct == 0)
        return pd_err_set(err, PD_EINVAL, "uy: no structure to apply it to");
    return structure_yield(&sc->st[sc->nstruct - 1], uy, 0.0, alpha, 0.0, err);
}

int pd_scene_yield_every(pd_scene *sc, double uy, double alpha, pd_err *err)
{
    if (!sc)
        return PD_NULL_ARG(err, "sc");
    int rc = PD_OK;
    for (int s = 0; s < sc->nstruct && !rc; s++)
        rc = structure_yield(&sc->st[s], NULL, uy, NULL, alpha, err);
    return rc;
}

int pd_scene_springs(const pd_scene *sc)
{
    int ns = 0;
    for (int s = 0; sc && s < sc->nstruct; s++)
        for (int i = 0; sc->st[s].uy && i < sc->st[s].storeys; i++)
            ns += isfinite(sc->st[s].uy[i]) && sc->st[s].yield_alpha[i] < 1.0;
    return ns;
}

int pd_scene_add_contact(pd_scene *sc, int a, int level_a, int b, int level_b, double gap,
                         double eps, int entry, pd_err *err)
{
    if (!sc)
        return PD_NULL_ARG(err, "sc");
    if (!(gap >= 0.0) || !isfinite(gap))
        return pd_err_set(err, PD_EINVAL, "gap: must be >= 0 (got %g)", gap);
    if (!(eps >= 0.0 && eps <= 1.0))
        return pd_err_set(err, PD_EINVAL, "eps: the restitution must be in [0, 1] (got %g)", eps);
    if (a == PD_WALL && b == PD_WALL)
        return pd_err_set(err, PD_EINVAL,
                          "b: a contact joins a structure to a wall or to "
                          "another structure, not two walls");
    if (a < PD_WALL || a >= sc->nstruct)
        return pd_err_set(err, PD_EINVAL, "a: no structure %d", a);
    if (b < PD_WALL || b >= sc->nstruct)
        return pd_err_set(err, PD_EINVAL, "b: no structure %d", b);
    if (a != PD_WALL && b != PD_WALL && !(a < b))
        return pd_err_set(err, PD_EINVAL,
                          "b: '%s' must stand to the right of '%s' (a is the left one, in file "
                          "order)",
                          sc->st[b].name, sc->st[a].name);
    if (a != PD_WALL && !(level_a >= 1 && level_a <= sc->st[a].storeys))
        return pd_err_set(err, PD_EINVAL, "levels: '%s' has no storey %d (it has %d)",
                          sc->st[a].name, level_a, sc->st[a].storeys);
    if (b != PD_WALL && !(level_b >= 1 && level_b <= sc->st[b].storeys))
        return pd_err_set(err, PD_EINVAL, "levels: '%s' has no storey %d (it has %d)",
                          sc->st[b].name, level_b, sc->st[b].storeys);
    if (grow((void **)&sc->ct, &sc->cap_contact, sc->ncontact + 1, sizeof *sc->ct))
        return pd_err_set(err, PD_ENOMEM, "out of memory for contact %d", sc->ncontact);
    sc->ct[sc->ncontact++] = (pd_contact){.a = a,
                                          .b = b,
                                          .level_a = a == PD_WALL ? 0 : level_a,
                                          .level_b = b == PD_WALL ? 0 : level_b,
                                          .gap = gap,
                                          .eps = eps,
                                          .entry = entry};
    sc->finished = 0;
    return PD_OK;
}

/* Number of eigenvalues below x of the symmetric tridiagonal (d, e):
 * negative pivots of the LDL^T of T - x I (Sturm count). */
static int sturm_count(int s, const double *d, const double *e, double x)
{
    int count = 0;
    double q = 1.0;
    for (int i = 0; i < s; i++) {
        double off = i > 0 ? e[i - 1] * e[i - 1] : 0.0;
        q = d[i] - x - (i > 0 ? off / q : 0.0);
        if (q == 0.0)
            q = -1e-300; /* an exact zero pivot counts as negative */
        count += q < 0.0;
    }
    return count;
}

/* The j-th smallest eigenvalue (1-based) of (d, e) by bisection on the
 * Sturm count, in [0, Gershgorin bound]. */
static double tridiag_eigenvalue(int s, const double *d, const double *e, int j)
{
    double lo = 0.0, hi = 0.0;
    for (int i = 0; i < s; i++)
        hi = fmax(hi, d[i] + (i > 0 ? fabs(e[i - 1]) : 0.0) + (i + 1 < s ? fabs(e[i]) : 0.0));
    for (int it = 0; it < 200 && hi - lo > 4e-16 * hi; it++) {
        double mid = 0.5 * (lo + hi);
        if (sturm_count(s, d, e, mid) >= j)
            hi = mid;
        else
            lo = mid;
    }
    return 0.5 * (lo + hi);
}

/* Circular frequencies of modes j1 and j2 of a structure (w[1] = w[0] when
 * there is one storey); PD_ENOMEM. */
static int structure_frequencies(const pd_structure *st, int j1, int j2, double w[2])
{
    int s = st->storeys;
    double *d = malloc((size_t)s * sizeof(double)), *e = malloc((size_t)s * sizeof(double));
    if (!d || !e) {
        free(d);
        free(e);
        return PD_ENOMEM;
    }
    for (int i = 0; i < s; i++) { /* M^-1/2 K M^-1/2 */
        double kup = i + 1 < s ? st->stiffness[i + 1] : 0.0;
        d[i] = (st->stiffness[i] + kup) / st->mass[i];
        e[i] = i + 1 < s ? -kup / sqrt(st->mass[i] * st->mass[i + 1]) : 0.0;
    }
    w[0] = sqrt(tridiag_eigenvalue(s, d, e, j1));
    w[1] = j2 <= s ? sqrt(tridiag_eigenvalue(s, d, e, j2)) : w[0];
    free(d);
    free(e);
    return PD_OK;
}

/* Periods and C = alpha M + beta K of one structure. */
static int structure_damping(pd_structure *st, pd_err *err)
{
    double w1[2], w[2];
    int rc;
    if ((rc = structure_frequencies(st, 1, st->storeys, w1)))
        return pd_err_set(err, rc, "out of memory for the modes of '%s'", st->name);
    st->T0 = PD_TWO_PI / w1[0];
    st->Tmin = PD_TWO_PI / w1[1];
    if (st->storeys == 1 || st->damping == PD_DAMPING_STIFFNESS) {
        st->period[0] = st->period[1] = st->T0;
        st->alpha = st->storeys == 1 ? 2.0 * st->xi * w1[0] : 0.0;
        st->beta = st->storeys == 1 ? 0.0 : 2.0 * st->xi / w1[0];
        return PD_OK;
    }
    if (!(st->modes[0] >= 1 && st->modes[1] > st->modes[0] && st->modes[1] <= st->storeys))
        return pd_err_set(err, PD_EINVAL,
                          "rayleigh_modes: '%s' needs two modes 1 <= i < j <= %d (got %d, %d)",
                          st->name, st->storeys, st->modes[0], st->modes[1]);
    if ((rc = structure_frequencies(st, st->modes[0], st->modes[1], w)))
        return pd_err_set(err, rc, "out of memory for the modes of '%s'", st->name);
    st->period[0] = PD_TWO_PI / w[0];
    st->period[1] = PD_TWO_PI / w[1];
    st->alpha = 2.0 * st->xi * w[0] * w[1] / (w[0] + w[1]);
    st->beta = 2.0 * st->xi / (w[0] + w[1]);
    return PD_OK;
}

/* The excitation in range; the message names the field. */
static int check_excitation(const pd_scene_excitation *x, pd_err *err)
{
    if (x->pulse != PD_PULSE_SINE && x->pulse != PD_PULSE_COSINE && x->pulse != PD_PULSE_HARMONIC)
        return pd_err_set(err, PD_EINVAL, "pulse: must be sine, cosine or harmonic");
    if (x->dir != 1 && x->dir != -1)
        return pd_err_set(err, PD_EINVAL, "dir: must be +x or -x");
    if (!positive(x->ap))
        return pd_err_set(err, PD_EINVAL, "ap: the pulse amplitude must be > 0 (got %g)", x->ap);
    if (!positive(x->Tp))
        return pd_err_set(err, PD_EINVAL, "Tp: the pulse period must be > 0 (got %g)", x->Tp);
    return PD_OK;
}

/* Entries of the contact matrices Moreau–Jean forms (What^-1 W, D =
 * W^T What^-1 W) at most: a building's What^-1 is dense, so its c contacts
 * fill c (c + storeys) of them; a row of 10^5 SDOFs needs 6 10^5, ten
 * buildings of 1000 storeys touching at every floor 6 10^7. */
#define SCENE_COUPLING_MAX 1e8

/* A contact's floors as a sortable key, with its index. */
typedef struct contact_key {
    int a, la, b, lb, k;
} contact_key;

static int key_cmp(const void *x, const void *y)
{
    const contact_key *p = x, *q = y;
    int d = p->a != q->a     ? (p->a > q->a) - (p->a < q->a)
            : p->la != q->la ? (p->la > q->la) - (p->la < q->la)
            : p->b != q->b   ? (p->b > q->b) - (p->b < q->b)
                             : (p->lb > q->lb) - (p->lb < q->lb);
    return d ? d : (p->k > q->k) - (p->k < q->k);
}

/* No two contacts join the same two floors (a redundant constraint: its
 * LCP is singular); PD_EINVAL naming the second entry. */
static int check_duplicates(const pd_scene *sc, pd_err *err)
{
    int m = sc->ncontact, rc = PD_OK;
    if (m < 2)
        return PD_OK;
    contact_key *key = malloc((size_t)m * sizeof *key);
    if (!key)
        return pd_err_set(err, PD_ENOMEM, "out of memory for %d contacts", m);
    for (int k = 0; k < m; k++)
        key[k] = (contact_key){.a = sc->ct[k].a,
                               .la = sc->ct[k].level_a,
                               .b = sc->ct[k].b,
                               .lb = sc->ct[k].level_b,
                               .k = k};
    qsort(key, (size_t)m, sizeof *key, key_cmp);
    for (int k = 1; k < m && !rc; k++) {
        const contact_key *p = &key[k - 1], *q = &key[k];
        if (p->a == q->a && p->la == q->la && p->b == q->b && p->lb == q->lb) {
            const pd_contact *c = &sc->ct[q->k];
            rc = pd_err_set(err, PD_EINVAL,
                            "contacts[%d]: '%s' storey %d and '%s' storey %d are "
                            "joined twice (also by contacts[%d])",
                            c->entry, c->a == PD_WALL ? "wall" : sc->st[c->a].name, c->level_a,
                            c->b == PD_WALL ? "wall" : sc->st[c->b].name, c->level_b,
                            sc->ct[p->k].entry);
        }
    }
    free(key);
    return rc;
}

/* The contact matrices' fill within SCENE_COUPLING_MAX, counted contact by
 * contact; PD_EINVAL naming the entry that passes it. */
static int check_coupling(const pd_scene *sc, pd_err *err)
{
    double fill = 0.0;
    long *c = calloc((size_t)sc->nstruct, sizeof *c);
    if (!c)
        return pd_err_set(err, PD_ENOMEM, "out of memory for %d structures", sc->nstruct);
    int rc = PD_OK;
    for (int k = 0; k < sc->ncontact && !rc; k++) {
        const int side[2] = {sc->ct[k].a, sc->ct[k].b};
        for (int j = 0; j < 2; j++) {
            int s = side[j];
            if (s == PD_WALL)
                continue;
            fill += 2.0 * (double)c[s] + 1.0 + sc->st[s].storeys; /* (c+1)(c+1+n) - c(c+n) */
            c[s]++;
        }
        if (!(fill <= SCENE_COUPLING_MAX))
            rc = pd_err_set(err, PD_EINVAL,
                            "contacts[%d]: the contacts up to here couple through "
                            "their structures into contact matrices of %.3g entries (at most "
                            "%.3g; %ld contacts on '%s')",
                            sc->ct[k].entry, fill, SCENE_COUPLING_MAX,
                            c[side[0] == PD_WALL ? side[1] : side[0]],
                            sc->st[side[0] == PD_WALL ? side[1] : side[0]].name);
    }
    free(c);
    return rc;
}

int pd_scene_finish(pd_scene *sc, pd_err *err)
{
    int rc, dof = 0;
    if (!sc)
        return PD_NULL_ARG(err, "sc");
    if (sc->nstruct == 0)
        return pd_err_set(err, PD_EINVAL, "structures: the row is empty");
    if ((rc = check_excitation(&sc->exc, err)))
        return rc;
    if (!(sc->tend >= 0.0) || !isfinite(sc->tend))
        return pd_err_set(err, PD_EINVAL, "tend: must be > 0 (got %g)", sc->tend);
    for (int s = 0; s < sc->nstruct; s++) {
        sc->st[s].dof = dof;
        if (dof > 2000000000 - sc->st[s].storeys)
            return pd_err_set(err, PD_EINVAL, "structures: too many storeys in the row");
        dof += sc->st[s].storeys;
        if ((rc = structure_damping(&sc->st[s], err)))
            return rc;
        const pd_structure *st = &sc->st[s];
        if (!positive(st->T0) || !isfinite(st->alpha) || !isfinite(st->beta))
            return pd_err_set(err, PD_EINVAL,
                              "structures: '%s' has a fundamental period of %g s "
                              "and damping coefficients %g, %g: not usable numbers (masses "
                              "and stiffnesses out of proportion?)",
                              st->name, st->T0, st->alpha, st->beta);
    }
    if ((rc = check_duplicates(sc, err)) || (rc = check_coupling(sc, err)))
        return rc;
    sc->n = dof;
    sc->finished = 1;
    return PD_OK;
}

double pd_scene_wp(const pd_scene *sc)
{
    return sc ? PD_TWO_PI / sc->exc.Tp : NAN;
}

double pd_scene_Le(const pd_scene *sc)
{
    if (!sc)
        return NAN;
    double wp = pd_scene_wp(sc);
    return sc->exc.ap / (wp * wp);
}

/* Longest and shortest fundamental periods, smallest damping. */
static void period_range(const pd_scene *sc, double *Tmin, double *Tmax, double *ximin)
{
    *Tmin = HUGE_VAL;
    *Tmax = 0.0;
    *ximin = 1.0;
    for (int s = 0; s < sc->nstruct; s++) {
        *Tmin = fmin(*Tmin, sc->st[s].T0);
        *Tmax = fmax(*Tmax, sc->st[s].T0);
        *ximin = fmin(*ximin, sc->st[s].xi);
    }
}

double pd_scene_default_dt(const pd_scene *sc)
{
    if (!sc)
        return NAN;
    double Tmin, Tmax, ximin;
    period_range(sc, &Tmin, &Tmax, &ximin);
    return fmin(sc->exc.Tp, Tmin) / 2000.0;
}

/* The oscillator's defaults with the longest period and the least damping. */
static pd_osc envelope_case(const pd_scene *sc)
{
    double Tmin, Tmax, ximin;
    period_range(sc, &Tmin, &Tmax, &ximin);
    pd_osc c = pd_osc_default();
    c.pulse = sc->exc.pulse;
    c.Tp = sc->exc.Tp;
    c.ap = sc->exc.ap;
    c.record = sc->exc.record;
    c.rec_ap = sc->exc.rec_ap;
    c.scale = sc->exc.scale;
    c.Pi2 = sc->exc.Tp / Tmax;
    c.xi = ximin;
    return c;
}

double pd_scene_default_tend(const pd_scene *sc)
{
    if (!sc)
        return NAN;
    pd_osc c = envelope_case(sc);
    return pd_osc_default_tend(&c);
}

double pd_scene_measure_start(const pd_scene *sc, double tend)
{
    if (!sc)
        return NAN;
    pd_osc c = envelope_case(sc);
    return pd_osc_measure_start(&c, tend);
}

/* Points per shortest period the methods that follow every mode take (the
 * oscillator's scan), and at most this many of them over a run, per
 * structure and contact element: about 10 s of the row reference (2 µs a
 * point on a stiff building), 25 s of event-general. */
#define SCENE_SCAN_DIV 64.0
#define SCENE_MAX_POINTS 5e6
/* The row reference evaluates a building's n storeys through its 2n modes
 * at every point: at most this many points times n^2 (a uniform building
 * of 50 storeys over 4.5 s: 2.3e7, 0.8 s; 100 storeys: 1.8e8, 17 s). */
#define SCENE_MAX_MODAL_WORK 1e8
/* The adaptive penalty follows an engaged Kelvin–Voigt element at about 11
 * steps a period at the default tolerances (rk8pd; a row of 10 at kc = 1e10
 * times its storeys' stiffness: 6.3e6 steps over 4 s, 35 s): its elements
 * count 16 points a period, at most 1e7 of them over the run. */
#define SCENE_PEN_DIV 16.0
#define SCENE_PEN_MAX_POINTS 1e7

/* The floor mass at storey level (1-based) of structure s; INFINITY at a wall. */
static double floor_mass(const pd_scene *sc, int s, int level)
{
    return s == PD_WALL ? INFINITY : sc->st[s].mass[level - 1];
}

/* The reduced mass of contact a's two floors (one floor's against a wall). */
static double contact_mass(const pd_scene *sc, int a)
{
    const pd_contact *ct = &sc->ct[a];
    double ma = floor_mass(sc, ct->a, ct->level_a), mb = floor_mass(sc, ct->b, ct->level_b);
    return isinf(ma) ? mb : isinf(mb) ? ma : ma * mb / (ma + mb);
}

/* The linear stiffness of the penalty elements [N/m]: kc, or for
 * Hertz-damp with kc_abs [N/m^1.5] its tangent at 1 % of Le
 * (pd_scene_contact_period_min). */
static double element_stiffness(const pd_scene *sc, const pd_run_opts *o)
{
    if (o->pen.law == PD_PENALTY_HERTZDAMP && o->pen.kc_abs > 0.0)
        return 1.5 * o->pen.kc_abs * sqrt(0.01 * pd_scene_Le(sc));
    return pd_scene_penalty_kc(sc, o);
}

/* The work of the methods that resolve every mode (all but Moreau–Jean,
 * whose implicit step is stable at any period) within their budget: a 64th
 * of the shortest period of each structure (and, for Kelvin–Voigt
 * elements, a 16th of each contact element's on its two floors) over the
 * run. */
static int check_budget(const pd_scene *sc, const pd_run_opts *o, pd_err *err)
{
    if (o->method == PD_METHOD_MOREAU || o->method == PD_METHOD_NEWMARK)
        return PD_OK; /* fixed implicit steps: the step budget (PD_MAX_STEPS) */
    const char *m = pd_method_name(o->method);
    for (int s = 0; s < sc->nstruct; s++) {
        const pd_structure *st = &sc->st[s];
        double pts = SCENE_SCAN_DIV * o->tend / st->Tmin;
        if (!(pts <= SCENE_MAX_POINTS))
            return pd_err_set(err, PD_EINVAL,
                              "structures[%d] ('%s'): its highest mode has a period of %.3g s; "
                              "--method %s would follow it at %.3g points over %.3g s (at most "
                              "%.3g): --method moreau runs it",
                              s, st->name, st->Tmin, m, pts, o->tend, SCENE_MAX_POINTS);
        double work = pts * st->storeys * (double)st->storeys;
        if (o->method == PD_METHOD_EVENT && st->storeys > 1 && !(work <= SCENE_MAX_MODAL_WORK))
            return pd_err_set(err, PD_EINVAL,
                              "structures[%d] ('%s'): --method event follows its %d storeys "
                              "through their modes, %.3g points times %d^2 over %.3g s (at most "
                              "%.3g): --method moreau runs it",
                              s, st->name, st->storeys, pts, st->storeys, o->tend,
                              SCENE_MAX_MODAL_WORK);
    }
    if (o->method != PD_METHOD_PENALTY || o->pen.law != PD_PENALTY_KELVIN)
        return PD_OK;
    double kc = pd_scene_penalty_kc(sc, o);
    for (int a = 0; a < sc->ncontact; a++) {
        const pd_contact *ct = &sc->ct[a];
        double mred = contact_mass(sc, a);
        double Tc = PD_TWO_PI * sqrt(mred / kc), pts = SCENE_PEN_DIV * o->tend / Tc;
        if (!(pts <= SCENE_PEN_MAX_POINTS))
            return pd_err_set(err, PD_EINVAL,
                              "contacts[%d]: its element (kc = %.3g N/m on %.3g kg) vibrates with "
                              "a period of %.3g s; --method penalty would follow it at %.3g "
                              "points over %.3g s (at most %.3g): a softer --kc, or --method "
                              "moreau, runs it",
                              ct->entry, kc, mred, Tc, pts, o->tend, SCENE_PEN_MAX_POINTS);
    }
    return PD_OK;
}

/* The shortest period of the penalty elements (Kelvin-Voigt's kc on the
 * contact's reduced mass; for Hertz-damp, the tangent 1.5 kc sqrt(d) at a
 * penetration of 1 % of Le, kc_abs in N/m^1.5): HUGE_VAL without contacts. */
double pd_scene_contact_period_min(const pd_scene *sc, const pd_run_opts *o)
{
    double mmin = HUGE_VAL, kc = element_stiffness(sc, o);
    for (int a = 0; a < sc->ncontact; a++)
        mmin = fmin(mmin, contact_mass(sc, a));
    return sc->ncontact ? PD_TWO_PI * sqrt(mmin / kc) : HUGE_VAL;
}

int pd_scene_resolve_opts(const pd_scene *sc, const pd_run_opts *in, pd_run_opts *out, pd_err *err)
{
    int rc;
    if (!sc || !out)
        return PD_NULL_ARG(err, !sc ? "sc" : "out");
    *out = in ? *in : pd_run_default_opts();
    if (!sc->finished)
        return pd_err_set(err, PD_EINVAL, "scene: not finished (pd_scene_finish)");
    if ((rc = pd_run_opts_check(out, err)))
        return rc;
    if (out->method == PD_METHOD_AUTO) /* a scene's default: Moreau-Jean */
        out->method = PD_METHOD_MOREAU;
    if (out->tend == 0.0)
        out->tend = sc->tend > 0.0 ? sc->tend : pd_scene_default_tend(sc);
    if (out->rtol > 0.0) /* to a tolerance: no step of its own */
        return PD_OK;
    if (out->dt == 0.0)
        out->dt = pd_scene_default_dt(sc);
    if (!(out->tend / out->dt <= PD_MAX_STEPS))
        return pd_err_set(err, PD_EINVAL, "dt: tend / dt = %g steps is too many (at most %.0e)",
                          out->tend / out->dt, PD_MAX_STEPS);
    return check_budget(sc, out, err);
}

int pd_scene_as_oscillator(const pd_scene *sc, pd_osc *c, int *mirrored)
{
    if (!sc || !c || !mirrored || !sc->finished || sc->nstruct != 1 || sc->st[0].storeys != 1 ||
        sc->ncontact > 1)
        return 0;
    const pd_contact *ct = sc->ncontact ? &sc->ct[0] : NULL;
    if (ct && ct->a != PD_WALL && ct->b != PD_WALL)
        return 0;
    *mirrored = ct && ct->a == PD_WALL; /* the wall on the left: x = -u */
    *c = (pd_osc){.pulse = sc->exc.pulse,
                  .dir = *mirrored ? -sc->exc.dir : sc->exc.dir,
                  .ap = sc->exc.ap,
                  .Tp = sc->exc.Tp,
                  .Pi2 = sc->exc.Tp / sc->st[0].T0,
                  .Pi3 = 0.0,
                  .eps = ct ? ct->eps : 0.0,
                  .xi = sc->st[0].xi,
                  .record = sc->exc.record,
                  .rec_ap = sc->exc.rec_ap,
                  .scale = sc->exc.scale};
    if (ct)
        pd_osc_set_gap(c, ct->gap);
    return 1;
}

/* ---- the engine model ------------------------------------------------------ */

/* F_i = m_i s phi(tau) (or the record's): the effective inertial forces along
 * x, in units of ap. */
static void scene_force(double tau, int side, double *F, void *ctx)
{
    const pd_scene_model *sm = ctx;
    double f = pd_osc_shape(&sm->shape, tau, side);
    for (int i = 0; i < sm->model.n; i++)
        F[i] = sm->mass[i] * f;
}

void pd_scene_model_free(pd_scene_model *sm)
{
    if (!sm)
        return;
    pd_sparse_free(&sm->M);
    pd_sparse_free(&sm->C);
    pd_sparse_free(&sm->K);
    pd_sparse_free(&sm->W);
    pd_sparse_free(&sm->S);
    free(sm->g0);
    free(sm->e);
    free(sm->mass);
    free(sm->ks);
    free(sm->uy);
    free(sm->spring_dof);
    free(sm->spring_alpha);
    memset(sm, 0, sizeof *sm);
}

/* Triplets of M, K, C (in reference units) and of W. */
typedef struct triplets {
    int *i, *j;
    double *x;
    long n;
} triplets;

static void tri_add(triplets *t, int i, int j, double x)
{
    t->i[t->n] = i;
    t->j[t->n] = j;
    t->x[t->n++] = x;
}

static int tri_alloc(triplets *t, long cap)
{
    t->n = 0;
    t->i = pd_malloc(cap, sizeof(int));
    t->j = pd_malloc(cap, sizeof(int));
    t->x = pd_malloc(cap, sizeof(double));
    return t->i && t->j && t->x ? PD_OK : PD_ENOMEM;
}

static void tri_free(triplets *t)
{
    free(t->i);
    free(t->j);
    free(t->x);
}

/* K / wp^2 (kscale) and C / wp = (alpha M + beta K) / wp of one structure. */
static void structure_triplets(const pd_structure *st, double wp, triplets *K, triplets *C,
                               triplets *M)
{
    int s = st->storeys, o = st->dof;
    for (int i = 0; i < s; i++) {
        double kup = i + 1 < s ? st->stiffness[i + 1] : 0.0, kii = st->stiffness[i] + kup;
        tri_add(M, o + i, o + i, st->mass[i]);
        tri_add(K, o + i, o + i, kii / (wp * wp));
        tri_add(C, o + i, o + i, (st->alpha * st->mass[i] + st->beta * kii) / wp);
        if (i + 1 < s) {
            tri_add(K, o + i, o + i + 1, -kup / (wp * wp));
            tri_add(K, o + i + 1, o + i, -kup / (wp * wp));
            if (st->beta != 0.0) {
                tri_add(C, o + i, o + i + 1, -st->beta * kup / wp);
                tri_add(C, o + i + 1, o + i, -st->beta * kup / wp);
            }
        }
    }
}

/* The dof of a contact's side, or -1 at a wall. */
static int side_dof(const pd_scene *sc, int s, int level)
{
    return s == PD_WALL ? -1 : sc->st[s].dof + level - 1;
}

/* The yielding springs' triplets of S and their constants (reference
 * units): one per storey with finite uy and alpha < 1, on its drift. */
static int spring_triplets(const pd_scene *sc, double wp, double Le, pd_scene_model *sm,
                           triplets *S)
{
    int ns = pd_scene_springs(sc), j = 0;
    sm->ks = pd_malloc(ns, sizeof(double));
    sm->uy = pd_malloc(ns, sizeof(double));
    sm->spring_dof = pd_malloc(ns, sizeof(int));
    sm->spring_alpha = pd_malloc(ns, sizeof(double));
    if (!sm->ks || !sm->uy || !sm->spring_dof || !sm->spring_alpha || tri_alloc(S, 2L * ns))
        return PD_ENOMEM;
    for (int s = 0; s < sc->nstruct; s++) {
        const pd_structure *st = &sc->st[s];
        for (int i = 0; st->uy && i < st->storeys; i++) {
            if (!isfinite(st->uy[i]) || !(st->yield_alpha[i] < 1.0))
                continue; /* an elastic storey */
            tri_add(S, st->dof + i, j, 1.0);
            if (i > 0)
                tri_add(S, st->dof + i - 1, j, -1.0);
            sm->ks[j] = (1.0 - st->yield_alpha[i]) * st->stiffness[i] / (wp * wp);
            sm->uy[j] = st->uy[i] / Le;
            sm->spring_dof[j] = st->dof + i;
            sm->spring_alpha[j++] = st->yield_alpha[i];
        }
    }
    return PD_OK;
}

int pd_scene_model_build(const pd_scene *sc, int with_contacts, pd_scene_model *sm, pd_err *err)
{
    triplets M = {0}, K = {0}, C = {0}, W = {0}, S = {0};
    if (!sc || !sm)
        return PD_NULL_ARG(err, !sc ? "sc" : "sm");
    int n = sc->n, m = with_contacts ? sc->ncontact : 0, rc = PD_OK;
    double wp = pd_scene_wp(sc), Le = pd_scene_Le(sc);
    memset(sm, 0, sizeof *sm);
    if (!sc->finished)
        return pd_err_set(err, PD_EINVAL, "scene: not finished (pd_scene_finish)");
    sm->g0 = pd_malloc(m, sizeof(double));
    sm->e = pd_malloc(m, sizeof(double));
    sm->mass = malloc((size_t)n * sizeof(double));
    if (!sm->g0 || !sm->e || !sm->mass || tri_alloc(&M, n) || tri_alloc(&K, 3L * n) ||
        tri_alloc(&C, 3L * n) || tri_alloc(&W, 2L * m)) {
        rc = pd_err_set(err, PD_ENOMEM, "out of memory for a model of %d dofs", n);
        goto done;
    }
    for (int s = 0; s < sc->nstruct; s++) {
        structure_triplets(&sc->st[s], wp, &K, &C, &M);
        for (int i = 0; i < sc->st[s].storeys; i++)
            sm->mass[sc->st[s].dof + i] = sc->st[s].mass[i];
    }
    for (int a = 0; a < m; a++) { /* g = gap + x_b - x_a */
        const pd_contact *ct = &sc->ct[a];
        int ia = side_dof(sc, ct->a, ct->level_a), ib = side_dof(sc, ct->b, ct->level_b);
        if (ia >= 0)
            tri_add(&W, ia, a, -1.0);
        if (ib >= 0)
            tri_add(&W, ib, a, 1.0);
        sm->g0[a] = ct->gap / Le;
        sm->e[a] = ct->eps;
    }
    int ns = pd_scene_springs(sc);
    if (spring_triplets(sc, wp, Le, sm, &S)) {
        rc = pd_err_set(err, PD_ENOMEM, "out of memory for %d yielding springs", ns);
        goto done;
    }
    if ((rc = pd_sparse_from_triplets(&sm->M, n, n, M.n, M.i, M.j, M.x, err)) ||
        (rc = pd_sparse_from_triplets(&sm->K, n, n, K.n, K.i, K.j, K.x, err)) ||
        (rc = pd_sparse_from_triplets(&sm->C, n, n, C.n, C.i, C.j, C.x, err)) ||
        (rc = pd_sparse_from_triplets(&sm->W, n, m, W.n, W.i, W.j, W.x, err)) ||
        (rc = pd_sparse_from_triplets(&sm->S, n, ns, S.n, S.i, S.j, S.x, err)))
        goto done;
    sm->shape = (pd_osc){.pulse = sc->exc.pulse,
                         .dir = sc->exc.dir,
                         .ap = sc->exc.ap,
                         .Tp = sc->exc.Tp,
                         .record = sc->exc.record,
                         .rec_ap = sc->exc.rec_ap,
                         .scale = sc->exc.scale};
    sm->breaks[0] = pd_osc_shape_end(&sm->shape); /* the pulse's or the record's end */
    sm->model = (pd_model){.n = n,
                           .m = m,
                           .M = pd_sparse_view(&sm->M),
                           .C = pd_sparse_view(&sm->C),
                           .K = pd_sparse_view(&sm->K),
                           .W = m > 0 ? pd_sparse_view(&sm->W) : pd_matrix_zero(n, 0),
                           .g0 = sm->g0,
                           .e = sm->e,
                           .force = scene_force,
                           .force_ctx = sm,
                           .breaks = sm->breaks,
                           .nbreaks = isfinite(sm->breaks[0]) ? 1 : 0,
                           .ns = ns,
                           .S = ns > 0 ? pd_sparse_view(&sm->S) : pd_matrix_zero(n, 0),
                           .ks = sm->ks,
                           .uy = sm->uy};
done:
    tri_free(&S);
    tri_free(&M);
    tri_free(&K);
    tri_free(&C);
    tri_free(&W);
    if (rc)
        pd_scene_model_free(sm);
    return rc;
}

int pd_scene_chain(int N, const pd_scene_excitation *exc, double T0, double ratio, double xi,
                   double gap, double eps, pd_scene **out, pd_err *err)
{
    pd_scene *sc;
    char name[PD_NAME_MAX];
    int rc = PD_OK;
    if (!out)
        return PD_NULL_ARG(err, "out");
    *out = NULL;
    if (N < 1 || N > 10000000)
        return pd_err_set(err, PD_EINVAL, "chain: N must be in [1, 1e7] (got %d)", N);
    if (!positive(ratio))
        return pd_err_set(err, PD_EINVAL, "chain-ratio: must be > 0 (got %g)", ratio);
    if (!(sc = pd_scene_new(exc)))
        return pd_err_set(err, PD_ENOMEM, "out of memory for a chain of %d", N);
    for (int i = 0; i < N && !rc; i++) {
        snprintf(name, sizeof name, "S%d", i + 1);
        rc = pd_scene_add_sdof(sc, name, i % 2 ? ratio * T0 : T0, xi, 1.0, err);
    }
    for (int i = 0; i <= N && !rc; i++)
        rc = pd_scene_add_contact(sc, i == 0 ? PD_WALL : i - 1, i == 0 ? 0 : 1,
                                  i == N ? PD_WALL : i, i == N ? 0 : 1, gap, eps, i, err);
    if (!rc)
        rc = pd_scene_finish(sc, err);
    if (rc) {
        pd_scene_free(sc);
        return rc;
    }
    *out = sc;
    return PD_OK;
}

/* Largest storey stiffness of the scene [N/m]. */
double pd_scene_stiffest(const pd_scene *sc)
{
    double k = 0.0;
    for (int s = 0; s < sc->nstruct; s++)
        for (int i = 0; i < sc->st[s].storeys; i++)
            k = fmax(k, sc->st[s].stiffness[i]);
    return k;
}

double pd_scene_penalty_kc(const pd_scene *sc, const pd_run_opts *o)
{
    if (o->pen.kc_abs > 0.0)
        return o->pen.kc_abs;
    return (o->pen.kc_mult > 0.0 ? o->pen.kc_mult : SCENE_PEN_KC) * pd_scene_stiffest(sc);
}

/* x excited by rec at scale: ap = scale times the fitted pulse's, Tp its. */
void pd_scene_excite_record(pd_scene_excitation *x, const pd_record *rec,
                            const pd_record_pulse *pulse, double scale)
{
    if (!x || !rec || !pulse)
        return;
    x->record = rec;
    x->scale = scale;
    x->rec_ap = pulse->ap;
    x->ap = scale * pulse->ap;
    x->Tp = pulse->Tp;
}
