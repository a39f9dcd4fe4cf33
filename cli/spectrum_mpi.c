/* spectrum_mpi.c — the few MPI calls a distributed sweep needs (the MPI
 * build, -DPD_MPI), and in the plain build a guard against being started by
 * mpirun, where every copy would compute and write the whole sweep.
 *
 * Protocol (spectrum_run.c): rank 0 hands out tasks in decreasing cost,
 * chunks on request, and computes from the same queue; workers report
 * finished tasks in batches; rank 0 stores, journals and counts them, and
 * alone writes the output. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pd_spectrum.h"

#ifdef PD_MPI
#include <mpi.h>

enum { TAG_REPORT = 7, TAG_GRANT = 8, TAG_TEXT = 9 };

int pd_spec_mpi_init(const char *cmd, int *rank, int *size, int *threaded)
{
    (void)cmd;
    int provided = MPI_THREAD_SINGLE, inited = 0;
    MPI_Initialized(&inited);
    if (!inited)
        MPI_Init_thread(NULL, NULL, MPI_THREAD_SERIALIZED, &provided);
    else
        MPI_Query_thread(&provided);
    MPI_Comm_rank(MPI_COMM_WORLD, rank);
    MPI_Comm_size(MPI_COMM_WORLD, size);
    *threaded = provided >= MPI_THREAD_SERIALIZED;
    return 0;
}

void pd_spec_mpi_finalize(void)
{
    int fin = 0;
    MPI_Finalized(&fin);
    if (!fin)
        MPI_Finalize();
}

void pd_spec_mpi_abort(int status)
{
    MPI_Abort(MPI_COMM_WORLD, status);
}

void pd_spec_mpi_agree(int *status)
{
    int mine = *status;
    MPI_Allreduce(&mine, status, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
}

int pd_spec_mpi_bcast_done(pd_spec_result *res, long ntasks)
{
    unsigned char *flags = malloc((size_t)ntasks + 1);
    int ok = flags != NULL, all_ok = 0;
    MPI_Allreduce(&ok, &all_ok, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (!all_ok) {
        free(flags);
        return -1;
    }
    for (long t = 0; t < ntasks; t++)
        flags[t] = (unsigned char)res[t].done;
    for (long off = 0; off < ntasks; off += 1L << 30) /* counts are ints */
        MPI_Bcast(flags + off, (int)(ntasks - off < (1L << 30) ? ntasks - off : 1L << 30),
                  MPI_UNSIGNED_CHAR, 0, MPI_COMM_WORLD);
    for (long t = 0; t < ntasks; t++)
        res[t].done = flags[t];
    free(flags);
    return 0;
}

void pd_spec_mpi_report(const pd_spec_report *m)
{
    MPI_Send(m, (int)sizeof *m, MPI_BYTE, 0, TAG_REPORT, MPI_COMM_WORLD);
}

int pd_spec_mpi_poll_report(int block, pd_spec_report *m, int *from)
{
    int flag = 1;
    MPI_Status st;
    if (!block)
        MPI_Iprobe(MPI_ANY_SOURCE, TAG_REPORT, MPI_COMM_WORLD, &flag, &st);
    if (!flag)
        return 0;
    MPI_Recv(m, (int)sizeof *m, MPI_BYTE, MPI_ANY_SOURCE, TAG_REPORT, MPI_COMM_WORLD, &st);
    *from = st.MPI_SOURCE;
    return 1;
}

void pd_spec_mpi_grant(int to, const pd_spec_grant *g)
{
    MPI_Send(g, (int)sizeof *g, MPI_BYTE, to, TAG_GRANT, MPI_COMM_WORLD);
}

int pd_spec_mpi_poll_grant(int block, pd_spec_grant *g)
{
    int flag = 1;
    MPI_Status st;
    if (!block)
        MPI_Iprobe(0, TAG_GRANT, MPI_COMM_WORLD, &flag, &st);
    if (!flag)
        return 0;
    MPI_Recv(g, (int)sizeof *g, MPI_BYTE, 0, TAG_GRANT, MPI_COMM_WORLD, &st);
    return 1;
}

void pd_mpi_bcast_bytes(void *p, long n)
{
    for (long off = 0; off < n; off += 1L << 30) /* counts are ints */
        MPI_Bcast((char *)p + off, (int)(n - off < (1L << 30) ? n - off : 1L << 30), MPI_BYTE, 0,
                  MPI_COMM_WORLD);
}

int pd_mpi_send_text(const char *text, size_t len)
{
    if (len > (size_t)1 << 30)
        return -1;
    MPI_Send(text, (int)len, MPI_CHAR, 0, TAG_TEXT, MPI_COMM_WORLD);
    return 0;
}

char *pd_mpi_recv_text(int block, size_t *len)
{
    int flag = 1, count = 0;
    MPI_Status st;
    if (block)
        MPI_Probe(MPI_ANY_SOURCE, TAG_TEXT, MPI_COMM_WORLD, &st);
    else
        MPI_Iprobe(MPI_ANY_SOURCE, TAG_TEXT, MPI_COMM_WORLD, &flag, &st);
    if (!flag)
        return NULL;
    MPI_Get_count(&st, MPI_CHAR, &count);
    char *buf = malloc((size_t)count + 1);
    if (!buf) { /* the ranks would wait for each other: end them all */
        fprintf(stderr, "pound: out of memory for a rank's message of %d bytes\n", count);
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    MPI_Recv(buf, count, MPI_CHAR, st.MPI_SOURCE, TAG_TEXT, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    buf[count] = '\0';
    *len = (size_t)count;
    return buf;
}

#else /* the plain build: one process */

/* The number of copies mpirun (OpenMPI or a PMI launcher) started, or 1. */
static long launched_copies(void)
{
    static const char *const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"};
    for (size_t i = 0; i < sizeof vars / sizeof vars[0]; i++) {
        const char *v = getenv(vars[i]);
        if (v && atol(v) > 1)
            return atol(v);
    }
    return 1;
}

int pd_spec_mpi_init(const char *cmd, int *rank, int *size, int *threaded)
{
    long copies = launched_copies();
    *rank = 0;
    *size = 1;
    *threaded = 1;
    if (copies > 1)
        return pd_cli_usage_error("%s: started by mpirun as one of %ld copies, but this "
                                  "pound has no MPI (each copy would compute and write the whole "
                                  "%s): build it with `make MPI=1` and run build-mpi/pound",
                                  cmd, copies, strcmp(cmd, "spectrum") ? "suite" : "sweep");
    return 0;
}

void pd_spec_mpi_finalize(void) {}

void pd_spec_mpi_abort(int status)
{
    (void)status;
}

void pd_spec_mpi_agree(int *status)
{
    (void)status;
}

int pd_spec_mpi_bcast_done(pd_spec_result *res, long ntasks)
{
    (void)res;
    (void)ntasks;
    return 0;
}

void pd_spec_mpi_report(const pd_spec_report *m)
{
    (void)m;
}

int pd_spec_mpi_poll_report(int block, pd_spec_report *m, int *from)
{
    (void)block;
    (void)m;
    (void)from;
    return 0;
}

void pd_spec_mpi_grant(int to, const pd_spec_grant *g)
{
    (void)to;
    (void)g;
}

int pd_spec_mpi_poll_grant(int block, pd_spec_grant *g)
{
    (void)block;
    (void)g;
    return 0;
}

void pd_mpi_bcast_bytes(void *p, long n)
{
    (void)p;
    (void)n;
}

int pd_mpi_send_text(const char *text, size_t len)
{
    (void)text;
    (void)len;
    return -1;
}

char *pd_mpi_recv_text(int block, size_t *len)
{
    (void)block;
    *len = 0;
    return NULL;
}

#endif
