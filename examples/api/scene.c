/* scene.c — a row built in code: a stiff and a flexible single-storey
 * structure 2 cm apart and a wall 5 cm to the right of the flexible one,
 * under a cosine pulse (docs/scenes.md has the same as a JSON file).
 * Prints umax per structure and the impacts per contact.  Exit 0 when the
 * run is finite and something struck.
 *
 *   cc scene.c $(pkg-config --cflags --libs pound) -lm -o scene */
#include <math.h>
#include <stdio.h>

#include <pound/pound.h>

/* Build the row: PD_OK, or an error whose message names the field. */
static int build(pd_scene *sc, pd_err *err)
{
    int rc;
    if ((rc = pd_scene_add_sdof(sc, "stiff", 0.4, 0.05, 2.0e5, err)) || /* T0 [s], xi, kg */
        (rc = pd_scene_add_sdof(sc, "flexible", 1.2, 0.05, 1.0e5, err)))
        return rc;
    /* structure 0 storey 1 against structure 1 storey 1, gap 2 cm, eps 0.65 */
    if ((rc = pd_scene_add_contact(sc, 0, 1, 1, 1, 0.02, 0.65, 0, err)) ||
        (rc = pd_scene_add_contact(sc, 1, 1, PD_WALL, 0, 0.05, 0.5, 1, err)))
        return rc;
    return pd_scene_finish(sc, err); /* numbers the dofs, derives damping */
}

int main(void)
{
    pd_scene_excitation exc = {
        .pulse = PD_PULSE_COSINE, .dir = 1, .ap = 3.0, .Tp = 0.6, .scale = 1.0};
    pd_scene *sc = pd_scene_new(&exc);
    pd_scene_result res = {0};
    pd_run_opts opts = pd_run_default_opts(); /* Moreau-Jean, dt and tend derived */
    pd_err err;
    long impacts = 0;
    int rc, ok = 1;
    if (!sc)
        return 1;
    opts.tend = 4.0;
    if ((rc = build(sc, &err)) || (rc = pd_scene_result_alloc(sc, &res, &err)) ||
        (rc = pd_scene_run(sc, &opts, NULL, NULL, &res, &err))) {
        fprintf(stderr, "scene: %s\n", err.msg);
        pd_scene_result_free(&res);
        pd_scene_free(sc);
        return 1;
    }
    printf("%d structures, %d dofs, %d contacts: %s, %ld steps of %g s\n", sc->nstruct, sc->n,
           sc->ncontact, res.method, res.steps, res.dt);
    for (int s = 0; s < sc->nstruct; s++) {
        double u = res.umax[sc->st[s].dof]; /* an SDOF: its one dof */
        printf("  %-10s T0 = %4.2f s  umax = %.6f m\n", sc->st[s].name, sc->st[s].T0, u);
        ok &= isfinite(u) && u > 0.0;
    }
    for (int k = 0; k < sc->ncontact; k++) {
        const pd_contact *ct = &sc->ct[k];
        printf("  contact %-20s impacts = %ld  first = %.4f s\n",
               ct->b == PD_WALL ? "flexible-wall" : "stiff-flexible", res.impacts[k],
               res.first_impact[k]);
        impacts += res.impacts[k];
    }
    pd_scene_result_free(&res);
    pd_scene_free(sc);
    return ok && impacts > 0 ? 0 : 1;
}
