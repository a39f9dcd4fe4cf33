/* pd_output.h — (cli) tables of columns plus attributes, written to HDF5 or
 * CSV through a temporary file renamed on success, so a failed run leaves
 * no partial file behind. */
#ifndef PD_OUTPUT_H
#define PD_OUTPUT_H

#include "pd_core.h"

typedef struct pd_attr {
    const char *name;
    const char *units; /* NULL or "" = dimensionless / none */
    int is_text;
    double num;
    const char *text;
} pd_attr;

typedef struct pd_column {
    const char *name;
    const char *units;
    const double *values;
} pd_column;

typedef struct pd_table {
    long rows;
    int ncols;
    const pd_column *cols;
    int nattrs;
    const pd_attr *attrs;
} pd_table;

/* Write the table to path: HDF5 when it ends in .h5/.hdf5, CSV when it
 * ends in .csv; anything else is PD_EINVAL. */
int pd_output_write(const char *path, const pd_table *table, pd_err *err);

/* PD_OK when path has a supported extension. */
int pd_output_check_path(const char *path, pd_err *err);

#endif
