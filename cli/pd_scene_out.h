/* pd_scene_out.h — (cli) what a scene run writes: its histories streamed
 * to HDF5 or CSV (scene_out.c), and the chart of its displacement
 * histories with the impacts marked (scene_plot.c). */
#ifndef PD_SCENE_OUT_H
#define PD_SCENE_OUT_H

#include "pd_problems.h"

/* What the files record besides the histories. */
typedef struct pd_scene_run_info {
    const pd_scene_summary *sum;
    const char *scene_name; /* the scene file, or "chain of N" */
} pd_scene_run_info;

typedef struct pd_scene_writer pd_scene_writer;

/* Open PATH.tmpPID (HDF5 for .h5/.hdf5, else CSV) for every every-th sample;
 * forces: the contacts' element forces too (the penalty methods). */
int pd_scene_writer_open(pd_scene_writer **w, const char *path, const pd_scene *sc, long every,
                         int forces, pd_err *err);
/* A pd_scene_sampler (ctx: the writer); asks the run to stop if a write fails. */
int pd_scene_writer_sample(const pd_scene_sample *s, void *ctx);
/* Write what is buffered and the results, close, rename into place. */
int pd_scene_writer_finish(pd_scene_writer *w, const pd_scene_run_info *ri, pd_err *err);
/* Release; an unfinished file is removed. */
void pd_scene_writer_free(pd_scene_writer *w);

typedef struct pd_scene_plot pd_scene_plot;

/* A decimated copy, for about `expected` samples, of the histories drawn:
 * up to four structures with contacts below their tops a panel each (their
 * contacts' storeys and top), else the top storeys of up to 12 structures
 * evenly spread over the row; and the impacts the samples report
 * (pd_scene_sample.impacts), each at its contact's storey. */
int pd_scene_plot_open(pd_scene_plot **p, const pd_scene *sc, long expected, pd_err *err);
int pd_scene_plot_sample(const pd_scene_sample *s, void *ctx);
/* Draw the histories, the walls and the impacts into png. */
int pd_scene_plot_draw(pd_scene_plot *p, const char *png, const char *title, pd_err *err);
void pd_scene_plot_free(pd_scene_plot *p);

#endif
