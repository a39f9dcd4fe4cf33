/* cmd_compare.c — `pound compare`: Moreau–Jean (and optionally penalty)
 * against the event-driven reference on one case. */
#include <math.h>
#include <string.h>

#include "pd_cli.h"

static const char compare_usage[] =
    "usage: pound compare [model flags | --scene F.json | --chain N] [--dt H] [--theta T]\n"
    "                     [--methods moreau[,penalty][,newmark][,event-general]] [--json]\n"
    "  errors against the event-driven reference on the step grid t_k = k dt:\n"
    "  err_umax_rel = |umax - umax_ref| / umax_ref,\n"
    "  err_hist_linf = max_k |u(t_k) - u_ref(t_k)| / umax_ref\n"
    "  scenes: per structure, over its storeys (scaled by its largest umax_ref); the\n"
    "  figures without a structure are the worst structure's; event-general (scenes):\n"
    "  the GSL-based general reference measured against the exact one\n";

enum { NMETHOD = PD_METHOD_NEWMARK + 1 }; /* want[] and the results by method code */

/* "moreau,penalty,event-general" -> flags by method code; 0 or 2. */
static int parse_methods(const char *list, int *want)
{
    char buf[128];
    int n = 0;
    if (!list || !*list || strlen(list) >= sizeof buf || list[strlen(list) - 1] == ',' ||
        list[0] == ',' || strstr(list, ",,"))
        return pd_cli_usage_error("--methods needs a list such as moreau,penalty");
    strcpy(buf, list);
    memset(want, 0, NMETHOD * sizeof *want);
    for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ","), n++) {
        pd_method m;
        if (pd_method_parse(tok, &m) || (m != PD_METHOD_MOREAU && m != PD_METHOD_PENALTY &&
                                         m != PD_METHOD_EVENT_GENERAL && m != PD_METHOD_NEWMARK))
            return pd_cli_usage_error("--methods: '%s' is not one of moreau, penalty, newmark, "
                                      "event-general",
                                      tok);
        want[m] = 1;
    }
    return n ? 0 : pd_cli_usage_error("--methods needs a list such as moreau,penalty");
}

/* Moreau–Jean (and penalty) against the reference on a scene. */
static int compare_scene(const pd_cli_case *k, const int *want, int json)
{
    pd_scene *sc = NULL;
    pd_scene_trace ref = {0};
    pd_scene_result rr = {0}, mr[NMETHOD];
    pd_scene_errors me[NMETHOD];
    pd_err err;
    int status, rc;
    memset(mr, 0, sizeof mr);
    memset(me, 0, sizeof me);
    if ((status = pd_cli_scene(k, &sc)))
        return status;
    if ((rc = pd_scene_trace_alloc(&ref, sc, &k->opts, &err)) ||
        (rc = pd_scene_result_alloc(sc, &rr, &err)) ||
        (rc = pd_scene_measure_reference(sc, &k->opts, &ref, &rr, &err))) {
        fprintf(stderr, "pound: compare: reference: %s\n", err.msg);
        status = rc == PD_EINVAL ? 2 : 1;
        goto done;
    }
    for (int m = 0; m < NMETHOD; m++) {
        pd_run_opts om = k->opts;
        om.method = (pd_method)m;
        if (want[m] && ((rc = pd_scene_result_alloc(sc, &mr[m], &err)) ||
                        (rc = pd_scene_errors_alloc(sc, &me[m], &err)) ||
                        (rc = pd_scene_measure_run(sc, &om, &ref, &rr, &mr[m], &me[m], &err)))) {
            fprintf(stderr, "pound: compare: %s: %s\n", pd_method_name((pd_method)m), err.msg);
            status = 1;
            goto done;
        }
    }
    long impacts_ref = 0;
    for (int a = 0; a < sc->ncontact; a++)
        impacts_ref += rr.impacts[a];
    int first = 0;
    while (!want[first])
        first++;
    if (json) {
        pd_json js;
        pd_json_init(&js, stdout);
        pd_json_begin_object(&js, NULL);
        pd_json_str(&js, "method", pd_method_name((pd_method)first));
        pd_json_num(&js, "err_umax_rel", me[first].err_umax_max);
        pd_json_num(&js, "err_hist_linf", me[first].err_hist_max);
        pd_json_int(&js, "impacts", me[first].impacts);
        pd_json_int(&js, "impacts_ref", impacts_ref);
        pd_json_num(&js, "cpu_s", me[first].cpu_s);
        pd_json_num(&js, "cpu_s_ref", rr.cpu_s);
        pd_json_int(&js, "events_ref", rr.steps);
        pd_cli_ref_decisions_json(&js, &rr);
        pd_json_num(&js, "dt", mr[first].dt);
        pd_json_begin_array(&js, "methods");
        for (int m = 0; m < NMETHOD; m++)
            if (want[m]) {
                pd_json_begin_object(&js, NULL);
                pd_json_str(&js, "method", pd_method_name((pd_method)m));
                pd_json_num(&js, "err_umax_rel", me[m].err_umax_max);
                pd_json_num(&js, "err_hist_linf", me[m].err_hist_max);
                pd_json_int(&js, "impacts", me[m].impacts);
                pd_json_int(&js, "steps", mr[m].steps);
                pd_json_num(&js, "cpu_s", me[m].cpu_s);
                pd_json_begin_array(&js, "structures");
                for (int s = 0; s < sc->nstruct; s++) {
                    pd_json_begin_object(&js, NULL);
                    pd_json_str(&js, "name", sc->st[s].name);
                    pd_json_num(&js, "err_umax_rel", me[m].err_umax[s]);
                    pd_json_num(&js, "err_hist_linf", me[m].err_hist[s]);
                    pd_json_end_object(&js);
                }
                pd_json_end_array(&js);
                pd_json_end_object(&js);
            }
        pd_json_end_array(&js);
        pd_json_end_object(&js);
        pd_json_finish(&js);
    } else {
        printf("scene %s: %d structures, dt = %.4g s; reference: %ld events, %ld impacts, "
               "%.3g s\n",
               k->scene_path ? k->scene_path : "(chain)", sc->nstruct, mr[first].dt, rr.steps,
               impacts_ref, rr.cpu_s);
        pd_cli_ref_decisions_text(stdout, &rr);
        printf("  %-13s %-14s %12s %12s %8s %10s\n", "method", "structure", "err_umax", "err_hist",
               "impacts", "cpu [s]");
        for (int m = 0; m < NMETHOD; m++)
            if (want[m]) {
                printf("  %-13s %-14s %12.3g %12.3g %8ld %10.3g\n", pd_method_name((pd_method)m),
                       "(worst)", me[m].err_umax_max, me[m].err_hist_max, me[m].impacts,
                       me[m].cpu_s);
                for (int s = 0; s < sc->nstruct && s < 40; s++)
                    printf("  %-13s %-14s %12.3g %12.3g\n", "", sc->st[s].name, me[m].err_umax[s],
                           me[m].err_hist[s]);
            }
    }
done:
    for (int m = 0; m < NMETHOD; m++) {
        pd_scene_result_free(&mr[m]);
        pd_scene_errors_free(&me[m]);
    }
    pd_scene_result_free(&rr);
    pd_scene_trace_free(&ref);
    pd_scene_free(sc);
    return status;
}

int pd_cmd_compare(int argc, char **argv)
{
    pd_cli_case k;
    int json = 0, want[NMETHOD] = {[PD_METHOD_MOREAU] = 1}, rc, status = 0;
    pd_cli_case_init(&k);
    k.methods_listed = 1;
    if (pd_cli_help(argc, argv, compare_usage, 1))
        return 0;
    for (int i = 1; i < argc; i++) {
        if ((rc = pd_cli_case_flag(&k, argc, argv, &i)) == 2)
            return 2;
        if (rc == 1)
            continue;
        if (!strcmp(argv[i], "--json"))
            json = 1;
        else if (!strcmp(argv[i], "--methods")) {
            if (parse_methods(i + 1 < argc ? argv[i + 1] : NULL, want))
                return 2;
            i++;
        } else
            return pd_cli_usage_error("compare: unknown flag '%s' (see pound compare --help)",
                                      argv[i]);
    }
    if ((rc = pd_cli_case_finish(&k)))
        return rc;
    if (k.have_rtol && !want[PD_METHOD_PENALTY]) {
        pd_cli_case_free(&k);
        return pd_cli_usage_error("--rtol: in compare the penalty rows' integrator tolerance "
                                  "(--methods ...,penalty); Moreau-Jean to a tolerance: "
                                  "simulate --rtol, or converge --methods moreau-rtol");
    }
    if (want[PD_METHOD_EVENT_GENERAL] && !pd_cli_is_scene(&k)) {
        pd_cli_case_free(&k);
        return pd_cli_usage_error("--methods: event-general is a reference for scenes (--scene, "
                                  "--chain); the oscillator's reference is exact");
    }
    if (pd_cli_is_scene(&k)) {
        rc = compare_scene(&k, want, json);
        pd_cli_case_free(&k);
        return rc;
    }

    pd_trace ref = {0}, work = {0};
    pd_osc_result rr;
    pd_measured mres[NMETHOD];
    pd_err err;
    if (pd_trace_alloc(&ref, &k.opts) || pd_trace_alloc(&work, &k.opts)) {
        fprintf(stderr, "pound: compare: out of memory for the histories\n");
        status = 1;
        goto done;
    }
    if ((rc = pd_measure_reference(&k.c, &k.opts, &ref, &rr, &err))) {
        fprintf(stderr, "pound: compare: reference: %s\n", err.msg);
        status = rc == PD_EINVAL ? 2 : 1;
        goto done;
    }
    for (int m = 0; m < NMETHOD; m++) {
        pd_run_opts om = k.opts;
        om.method = (pd_method)m;
        if (want[m] && (rc = pd_measure_run(&k.c, &om, &ref, rr.umax, &work, &mres[m], &err))) {
            fprintf(stderr, "pound: compare: %s: %s\n", pd_method_name((pd_method)m), err.msg);
            status = 1;
            goto done;
        }
    }
    int first = 0;
    while (first < NMETHOD - 1 && !want[first])
        first++;
    if (json) {
        pd_json js;
        pd_json_init(&js, stdout);
        pd_json_begin_object(&js, NULL);
        pd_json_str(&js, "method", pd_method_name((pd_method)first));
        pd_json_num(&js, "err_umax_rel", mres[first].err_umax_rel);
        pd_json_num(&js, "err_hist_linf", mres[first].err_hist_linf);
        pd_json_int(&js, "impacts", mres[first].r.impacts);
        pd_json_int(&js, "impacts_ref", rr.impacts);
        pd_json_num(&js, "cpu_s", mres[first].r.cpu_s);
        pd_json_num(&js, "cpu_s_ref", rr.cpu_s);
        pd_json_num(&js, "umax", mres[first].r.umax);
        pd_json_num(&js, "umax_ref", rr.umax);
        pd_json_int(&js, "events_ref", rr.steps);
        pd_json_int(&js, "accumulations_ref", rr.accumulations);
        pd_json_num(&js, "dt", k.opts.dt);
        pd_json_num(&js, "Pi2", k.c.Pi2);
        pd_json_num(&js, "Pi3", k.c.Pi3);
        pd_json_num(&js, "eps", k.c.eps);
        pd_json_begin_array(&js, "methods");
        for (int m = 0; m < NMETHOD; m++)
            if (want[m]) {
                pd_json_begin_object(&js, NULL);
                pd_json_str(&js, "method", pd_method_name((pd_method)m));
                pd_json_num(&js, "err_umax_rel", mres[m].err_umax_rel);
                pd_json_num(&js, "err_hist_linf", mres[m].err_hist_linf);
                pd_json_int(&js, "impacts", mres[m].r.impacts);
                pd_json_int(&js, "steps", mres[m].r.steps);
                pd_json_num(&js, "cpu_s", mres[m].r.cpu_s);
                pd_json_end_object(&js);
            }
        pd_json_end_array(&js);
        pd_json_end_object(&js);
        pd_json_finish(&js);
    } else {
        printf("%s %s pulse, Pi2 = %.6g, Pi3 = %.6g, eps = %g, xi = %g, dt = %.4g s\n",
               pd_dir_name(k.c.dir), pd_osc_excitation_name(&k.c), k.c.Pi2, k.c.Pi3, k.c.eps,
               k.c.xi, k.opts.dt);
        printf("  %-10s %14s %12s %12s %8s %10s\n", "method", "umax [m]", "err_umax", "err_hist",
               "impacts", "cpu [s]");
        printf("  %-10s %14.9g %12s %12s %8ld %10.3g\n", "event", rr.umax, "(ref)", "(ref)",
               rr.impacts, rr.cpu_s);
        for (int m = 0; m < NMETHOD; m++)
            if (want[m])
                printf("  %-10s %14.9g %12.3g %12.3g %8ld %10.3g\n", pd_method_name((pd_method)m),
                       mres[m].r.umax, mres[m].err_umax_rel, mres[m].err_hist_linf,
                       mres[m].r.impacts, mres[m].r.cpu_s);
    }
done:
    pd_cli_case_free(&k);
    pd_trace_free(&ref);
    pd_trace_free(&work);
    return status;
}
