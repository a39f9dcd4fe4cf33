/* h5.c — (cli) the HDF5 helpers the output writers share. */
#include <stdio.h>
#include <string.h>

#include "pd_h5.h"

/* A scalar attribute: text when text is non-NULL, else the number x. */
int pd_h5_attr(hid_t obj, const char *name, const char *text, double x)
{
    hid_t space = H5Screate(H5S_SCALAR), type = -1, attr = -1;
    herr_t st = -1;
    if (space < 0)
        return -1;
    if (text) {
        type = H5Tcopy(H5T_C_S1);
        if (type >= 0 && H5Tset_size(type, strlen(text) + 1) >= 0 &&
            (attr = H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT)) >= 0)
            st = H5Awrite(attr, type, text);
    } else if ((attr = H5Acreate2(obj, name, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT,
                                  H5P_DEFAULT)) >= 0)
        st = H5Awrite(attr, H5T_NATIVE_DOUBLE, &x);
    if (attr >= 0)
        H5Aclose(attr);
    if (type >= 0)
        H5Tclose(type);
    H5Sclose(space);
    return st < 0 ? -1 : 0;
}

/* A number attribute with its "<name>_units" companion (units NULL: none). */
int pd_h5_num(hid_t obj, const char *name, double x, const char *units)
{
    char uname[160];
    if (pd_h5_attr(obj, name, NULL, x))
        return -1;
    snprintf(uname, sizeof uname, "%s_units", name);
    return units ? pd_h5_attr(obj, uname, units, 0.0) : 0;
}

/* A 1-D double array attribute of n values with its units companion. */
int pd_h5_nums(hid_t obj, const char *name, int n, const double *x, const char *units)
{
    char uname[160];
    hsize_t dims[1] = {(hsize_t)(n > 0 ? n : 1)};
    double zero = 0.0;
    hid_t space = H5Screate_simple(1, dims, NULL), attr = -1;
    herr_t st = -1;
    if (space < 0)
        return -1;
    if ((attr = H5Acreate2(obj, name, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT)) >= 0)
        st = H5Awrite(attr, H5T_NATIVE_DOUBLE, n > 0 ? x : &zero);
    if (attr >= 0 && H5Aclose(attr) < 0)
        st = -1;
    H5Sclose(space);
    if (st < 0)
        return -1;
    snprintf(uname, sizeof uname, "%s_units", name);
    return units ? pd_h5_attr(obj, uname, units, 0.0) : 0;
}

/* An object-creation property list without modification times (so equal
 * runs give byte-identical files). */
hid_t pd_h5_untimed(hid_t cls)
{
    hid_t p = H5Pcreate(cls);
    if (p >= 0 && H5Pset_obj_track_times(p, 0) < 0) {
        H5Pclose(p);
        return -1;
    }
    return p;
}

/* An extendible chunked dataset of rows x cols (cols 0: 1-D) of type with units. */
hid_t pd_h5_extendible(hid_t loc, const char *name, hid_t type, int cols, long chunk,
                       const char *units)
{
    int rank = cols > 0 ? 2 : 1;
    hsize_t dims[2] = {0, (hsize_t)cols}, maxd[2] = {H5S_UNLIMITED, (hsize_t)cols};
    hsize_t ch[2] = {(hsize_t)chunk, (hsize_t)(cols > 0 ? cols : 1)};
    hid_t space = H5Screate_simple(rank, dims, maxd), dcpl = pd_h5_untimed(H5P_DATASET_CREATE);
    hid_t ds = -1;
    if (space >= 0 && dcpl >= 0 && H5Pset_chunk(dcpl, rank, ch) >= 0)
        ds = H5Dcreate2(loc, name, type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    if (ds >= 0 && pd_h5_attr(ds, "units", units, 0.0)) {
        H5Dclose(ds);
        ds = -1;
    }
    if (dcpl >= 0)
        H5Pclose(dcpl);
    if (space >= 0)
        H5Sclose(space);
    return ds;
}

/* Append nrows x cols values (row-major) to an extendible dataset at row r0. */
int pd_h5_append(hid_t ds, hid_t type, long r0, long nrows, int cols, const void *x)
{
    int rank = cols > 0 ? 2 : 1;
    hsize_t size[2] = {(hsize_t)(r0 + nrows), (hsize_t)cols};
    hsize_t start[2] = {(hsize_t)r0, 0}, count[2] = {(hsize_t)nrows, (hsize_t)cols};
    if (H5Dset_extent(ds, size) < 0)
        return -1;
    hid_t fs = H5Dget_space(ds), ms = H5Screate_simple(rank, count, NULL);
    int rc = fs < 0 || ms < 0 ||
             H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, NULL, count, NULL) < 0 ||
             H5Dwrite(ds, type, ms, fs, H5P_DEFAULT, x) < 0;
    if (ms >= 0)
        H5Sclose(ms);
    if (fs >= 0)
        H5Sclose(fs);
    return rc ? -1 : 0;
}

