/* output.c — write a pd_table to HDF5 or CSV, atomically. */
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pd_h5.h"
#include "pd_output.h"

/* Does path end with suffix? */
static int ends_with(const char *path, const char *suffix)
{
    size_t n = strlen(path), k = strlen(suffix);
    return n > k && !strcmp(path + n - k, suffix);
}

static int is_hdf5(const char *path) { return ends_with(path, ".h5") || ends_with(path, ".hdf5"); }

int pd_output_check_path(const char *path, pd_err *err)
{
    if (is_hdf5(path) || ends_with(path, ".csv"))
        return PD_OK;
    return pd_err_set(err, PD_EINVAL, "-o %s: the file name must end in .h5, .hdf5 or .csv", path);
}

/* Attribute name plus its "<name>_units" companion. */
static int h5_attr_with_units(hid_t obj, const pd_attr *a)
{
    char uname[128];
    if (pd_h5_attr(obj, a->name, a->is_text ? a->text : NULL, a->num))
        return -1;
    if (a->units && a->units[0]) {
        snprintf(uname, sizeof uname, "%s_units", a->name);
        return pd_h5_attr(obj, uname, a->units, 0.0);
    }
    return 0;
}

/* One 1-D dataset with a "units" attribute. */
static int h5_column(hid_t file, const pd_column *c, long rows)
{
    hsize_t dims[1] = {(hsize_t)rows};
    hid_t space = H5Screate_simple(1, dims, NULL), ds = -1;
    int rc = -1;
    if (space < 0)
        return -1;
    ds = H5Dcreate2(file, c->name, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT,
                    H5P_DEFAULT);
    if (ds >= 0 && (rows == 0 || H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                                          c->values) >= 0)) {
        rc = pd_h5_attr(ds, "units", c->units ? c->units : "", 0.0);
    }
    if (ds >= 0)
        H5Dclose(ds);
    H5Sclose(space);
    return rc;
}

static int write_hdf5(const char *path, const pd_table *t)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL); /* the library must not print */
    hid_t file = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    int rc = 0;
    if (file < 0)
        return -1;
    for (int i = 0; i < t->nattrs && !rc; i++)
        rc = h5_attr_with_units(file, &t->attrs[i]);
    for (int j = 0; j < t->ncols && !rc; j++)
        rc = h5_column(file, &t->cols[j], t->rows);
    if (H5Fclose(file) < 0)
        rc = -1;
    return rc;
}

/* CSV: "# name = value [units]" lines, a header row, then the columns. */
static int write_csv(const char *path, const pd_table *t)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    for (int i = 0; i < t->nattrs; i++) {
        const pd_attr *a = &t->attrs[i];
        if (a->is_text)
            fprintf(f, "# %s = %s", a->name, a->text);
        else
            fprintf(f, "# %s = %.17g", a->name, a->num);
        if (a->units && a->units[0])
            fprintf(f, " [%s]", a->units);
        fputc('\n', f);
    }
    for (int j = 0; j < t->ncols; j++)
        fprintf(f, "%s%s", j ? "," : "", t->cols[j].name);
    fputc('\n', f);
    for (long r = 0; r < t->rows; r++)
        for (int j = 0; j < t->ncols; j++)
            fprintf(f, "%.17g%c", t->cols[j].values[r], j + 1 < t->ncols ? ',' : '\n');
    int bad = ferror(f);
    return (fclose(f) != 0 || bad) ? -1 : 0;
}

int pd_output_write(const char *path, const pd_table *table, pd_err *err)
{
    char tmp[4096];
    int rc;
    if ((rc = pd_output_check_path(path, err)))
        return rc;
    if (snprintf(tmp, sizeof tmp, "%s.tmp%ld", path, (long)getpid()) >= (int)sizeof tmp)
        return pd_err_set(err, PD_EINVAL, "-o %s: path too long", path);
    rc = is_hdf5(path) ? write_hdf5(tmp, table) : write_csv(tmp, table);
    if (rc || rename(tmp, path) != 0) {
        unlink(tmp);
        return pd_err_set(err, PD_EIO, "-o %s: cannot write the file", path);
    }
    return PD_OK;
}
