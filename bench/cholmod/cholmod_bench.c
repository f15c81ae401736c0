/*
 * CHOLMOD numeric-factorisation benchmark for a matrix exported by bench_core.
 *
 * Input file (little endian):
 *   8 bytes  magic "ADHKBAR1"
 *   u64      n, nnz, has_perm
 *   u64      col_ptr[n + 1]      upper triangle, compressed sparse column,
 *   u64      row_idx[nnz]        row indices sorted within each column
 *   f64      values[nnz]
 *   u64      perm[n]             only if has_perm: perm[k] = original index of the
 *                                k-th pivot (the elimination order used by faer)
 *
 * For every requested ordering (metis, given, nesdis, amd) and mode (supernodal,
 * simplicial) the matrix is analysed once, then cholmod_l_factorize is timed over
 * --reps repetitions (after one warm-up call, kept as the first sample when it takes
 * more than 2 s) for every requested BLAS thread count
 * (simplicial: first thread count only, as it does not use the BLAS). For the METIS
 * ordering the driver also reports which mode CHOLMOD's default (CHOLMOD_AUTO) selects.
 * One line per configuration is printed:
 *
 *   result ordering=metis mode=supernodal threads=1 median_s=... min_s=... ...
 *
 * Usage: cholmod_bench FILE [--reps N] [--threads 1,2] [--orderings metis,given]
 *                           [--modes supernodal,simplicial] [--simplicial-max-gflop X]
 */

#include <cholmod.h>
#include <dlfcn.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define MAX_LIST 8
/* A warm-up factorisation longer than this [s] is kept as the first sample. */
#define LONG_RUN_S 2.0

typedef struct {
    int64_t n, nnz;
    int64_t *col_ptr, *row_idx, *perm;
    double *values;
} matrix_file;

typedef struct {
    const char *path;
    int reps;
    int threads[MAX_LIST];
    int n_threads;
    char orderings[MAX_LIST][16];
    int n_orderings;
    char modes[MAX_LIST][16];
    int n_modes;
    double simplicial_max_gflop;
} options;

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void die(const char *msg) {
    fprintf(stderr, "cholmod_bench: %s\n", msg);
    exit(1);
}

static void read_exact(FILE *f, void *dst, size_t bytes) {
    if (fread(dst, 1, bytes, f) != bytes) die("truncated matrix file");
}

static matrix_file read_matrix(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f) die("cannot open matrix file");
    char magic[8];
    read_exact(f, magic, 8);
    if (memcmp(magic, "ADHKBAR1", 8) != 0) die("not an ADHKBAR1 file");
    uint64_t header[3];
    read_exact(f, header, sizeof header);
    matrix_file m;
    m.n = (int64_t)header[0];
    m.nnz = (int64_t)header[1];
    m.col_ptr = malloc(sizeof(int64_t) * (size_t)(m.n + 1));
    m.row_idx = malloc(sizeof(int64_t) * (size_t)m.nnz);
    m.values = malloc(sizeof(double) * (size_t)m.nnz);
    m.perm = NULL;
    if (!m.col_ptr || !m.row_idx || !m.values) die("out of memory");
    read_exact(f, m.col_ptr, sizeof(int64_t) * (size_t)(m.n + 1));
    read_exact(f, m.row_idx, sizeof(int64_t) * (size_t)m.nnz);
    read_exact(f, m.values, sizeof(double) * (size_t)m.nnz);
    if (header[2]) {
        m.perm = malloc(sizeof(int64_t) * (size_t)m.n);
        if (!m.perm) die("out of memory");
        read_exact(f, m.perm, sizeof(int64_t) * (size_t)m.n);
    }
    fclose(f);
    return m;
}

static int split_list(const char *arg, char out[][16]) {
    int count = 0;
    const char *p = arg;
    while (*p && count < MAX_LIST) {
        const char *comma = strchr(p, ',');
        size_t len = comma ? (size_t)(comma - p) : strlen(p);
        if (len == 0 || len >= 16) die("bad list argument");
        memcpy(out[count], p, len);
        out[count][len] = '\0';
        count++;
        if (!comma) break;
        p = comma + 1;
    }
    return count;
}

static options parse_options(int argc, char **argv) {
    options o;
    memset(&o, 0, sizeof o);
    o.reps = 5;
    o.threads[0] = 1;
    o.n_threads = 1;
    strcpy(o.orderings[0], "metis");
    o.n_orderings = 1;
    strcpy(o.modes[0], "supernodal");
    o.n_modes = 1;
    o.simplicial_max_gflop = 20.0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--reps") == 0 && v) {
            o.reps = atoi(v);
            i++;
        } else if (strcmp(a, "--threads") == 0 && v) {
            char items[MAX_LIST][16];
            o.n_threads = split_list(v, items);
            for (int k = 0; k < o.n_threads; k++) o.threads[k] = atoi(items[k]);
            i++;
        } else if (strcmp(a, "--orderings") == 0 && v) {
            o.n_orderings = split_list(v, o.orderings);
            i++;
        } else if (strcmp(a, "--modes") == 0 && v) {
            o.n_modes = split_list(v, o.modes);
            i++;
        } else if (strcmp(a, "--simplicial-max-gflop") == 0 && v) {
            o.simplicial_max_gflop = atof(v);
            i++;
        } else if (a[0] != '-' && !o.path) {
            o.path = a;
        } else {
            die("usage: cholmod_bench FILE [--reps N] [--threads 1,2] "
                "[--orderings metis,given,nesdis,amd] [--modes supernodal,simplicial] "
                "[--simplicial-max-gflop X]");
        }
    }
    if (!o.path) die("missing matrix file");
    if (o.reps < 1) o.reps = 1;
    return o;
}

/* BLAS and OpenMP thread control, looked up at run time so that the same binary
 * works with the reference BLAS and with OpenBLAS. */
typedef void (*set_threads_fn)(int);
typedef char *(*get_config_fn)(void);

static const char *blas_name(void) {
    get_config_fn cfg = (get_config_fn)dlsym(RTLD_DEFAULT, "openblas_get_config");
    if (cfg) return cfg();
    return "reference BLAS (single-threaded)";
}

static int set_threads(int t) {
    int controlled = 0;
    set_threads_fn blas = (set_threads_fn)dlsym(RTLD_DEFAULT, "openblas_set_num_threads");
    if (blas) {
        blas(t);
        controlled = 1;
    }
    set_threads_fn omp = (set_threads_fn)dlsym(RTLD_DEFAULT, "omp_set_num_threads");
    if (omp) omp(t);
    return controlled;
}

static int ordering_code(const char *name) {
    if (strcmp(name, "metis") == 0) return CHOLMOD_METIS;
    if (strcmp(name, "nesdis") == 0) return CHOLMOD_NESDIS;
    if (strcmp(name, "amd") == 0) return CHOLMOD_AMD;
    if (strcmp(name, "given") == 0) return CHOLMOD_GIVEN;
    die("unknown ordering");
    return -1;
}

static const char *ordering_label(int code) {
    switch (code) {
    case CHOLMOD_NATURAL: return "natural";
    case CHOLMOD_GIVEN: return "given";
    case CHOLMOD_AMD: return "amd";
    case CHOLMOD_METIS: return "metis";
    case CHOLMOD_NESDIS: return "nesdis";
    case CHOLMOD_COLAMD: return "colamd";
    case CHOLMOD_POSTORDERED: return "postordered";
    default: return "other";
    }
}

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Stored entries and sum of squared column counts (a flop measure) of a supernodal
 * factor, amalgamation zeros included. */
static void supernodal_size(const cholmod_factor *L, double *stored, double *flops) {
    const int64_t *super = L->super, *pi = L->pi;
    double s_stored = 0.0, s_flops = 0.0;
    for (size_t s = 0; s < L->nsuper; s++) {
        int64_t ncol = super[s + 1] - super[s];
        int64_t nrow = pi[s + 1] - pi[s];
        s_stored += (double)ncol * (double)nrow;
        for (int64_t j = 0; j < ncol; j++) {
            double c = (double)(nrow - j);
            s_flops += c * c;
        }
    }
    *stored = s_stored;
    *flops = s_flops;
}

/* Relative error of the solution of A x = A 1. */
static double solve_error(cholmod_sparse *A, cholmod_factor *L, cholmod_common *c) {
    int64_t n = (int64_t)A->nrow;
    cholmod_dense *ones = cholmod_l_ones(A->nrow, 1, CHOLMOD_REAL, c);
    cholmod_dense *b = cholmod_l_zeros(A->nrow, 1, CHOLMOD_REAL, c);
    double alpha[2] = {1.0, 0.0}, beta[2] = {0.0, 0.0};
    cholmod_l_sdmult(A, 0, alpha, beta, ones, b, c);
    cholmod_dense *x = cholmod_l_solve(CHOLMOD_A, L, b, c);
    double err = INFINITY;
    if (x) {
        const double *xv = x->x;
        err = 0.0;
        for (int64_t i = 0; i < n; i++) err = fmax(err, fabs(xv[i] - 1.0));
        cholmod_l_free_dense(&x, c);
    }
    cholmod_l_free_dense(&ones, c);
    cholmod_l_free_dense(&b, c);
    return err;
}

static void run_configuration(const options *o, const matrix_file *m, cholmod_sparse *A,
                              const char *ordering, const char *mode) {
    int wanted = ordering_code(ordering);
    int supernodal = strcmp(mode, "supernodal") == 0;
    if (!supernodal && strcmp(mode, "simplicial") != 0) die("unknown mode");
    if (wanted == CHOLMOD_GIVEN && !m->perm) {
        printf("skipped ordering=given mode=%s reason=no_permutation_in_file\n", mode);
        return;
    }

    cholmod_common c;
    cholmod_l_start(&c);
    c.print = 0;
    c.nmethods = 1;
    c.method[0].ordering = wanted;
    c.postorder = 1;
    c.supernodal = supernodal ? CHOLMOD_SUPERNODAL : CHOLMOD_SIMPLICIAL;
    c.final_ll = 1;

    int64_t *perm = wanted == CHOLMOD_GIVEN ? m->perm : NULL;
    double t0 = now_s();
    cholmod_factor *L = cholmod_l_analyze_p(A, perm, NULL, 0, &c);
    double analyse_s = now_s() - t0;
    if (!L && wanted == CHOLMOD_METIS && c.status == CHOLMOD_NOT_INSTALLED) {
        printf("note metis_unavailable=1 fallback=amd\n");
        c.status = CHOLMOD_OK;
        c.method[0].ordering = CHOLMOD_AMD;
        t0 = now_s();
        L = cholmod_l_analyze_p(A, NULL, NULL, 0, &c);
        analyse_s = now_s() - t0;
    }
    if (!L || c.status < CHOLMOD_OK) {
        printf("failed ordering=%s mode=%s stage=analyse status=%d\n", ordering, mode, c.status);
        if (L) cholmod_l_free_factor(&L, &c);
        cholmod_l_finish(&c);
        return;
    }
    const char *used = ordering_label(L->ordering);
    double lnz = c.lnz, fl = c.fl;

    if (!supernodal && fl > o->simplicial_max_gflop * 1e9) {
        printf("skipped ordering=%s mode=simplicial reason=flops_%.3g_above_limit\n", used, fl);
        cholmod_l_free_factor(&L, &c);
        cholmod_l_finish(&c);
        return;
    }

    if (supernodal && wanted != CHOLMOD_GIVEN) {
        /* What CHOLMOD's default (CHOLMOD_AUTO) would choose with this ordering. */
        cholmod_common a;
        cholmod_l_start(&a);
        a.print = 0;
        a.nmethods = 1;
        a.method[0].ordering = c.method[0].ordering;
        cholmod_factor *La = cholmod_l_analyze(A, &a);
        if (La) {
            printf("note ordering=%s auto_mode=%s flops_per_lnz=%.1f supernodal_switch=%.0f\n",
                   ordering_label(La->ordering), La->is_super ? "supernodal" : "simplicial",
                   a.fl / a.lnz, a.supernodal_switch);
            cholmod_l_free_factor(&La, &a);
        }
        cholmod_l_finish(&a);
    }

    /* The simplicial factorisation does not call the BLAS: one thread count suffices. */
    int n_threads = supernodal ? o->n_threads : 1;
    double *samples = malloc(sizeof(double) * (size_t)o->reps);
    for (int ti = 0; ti < n_threads; ti++) {
        int threads = o->threads[ti];
        int controlled = set_threads(threads);
        if (!controlled && threads > 1) {
            printf("skipped ordering=%s mode=%s threads=%d reason=blas_threads_not_controllable\n",
                   used, mode, threads);
            continue;
        }
        t0 = now_s();
        int ok = cholmod_l_factorize(A, L, &c);
        double first = now_s() - t0;
        if (!ok || c.status != CHOLMOD_OK || L->minor < (size_t)m->n) {
            printf("failed ordering=%s mode=%s stage=factorize status=%d\n", used, mode, c.status);
            break;
        }
        int r0 = 0;
        if (first > LONG_RUN_S) samples[r0++] = first;
        for (int r = r0; r < o->reps; r++) {
            t0 = now_s();
            cholmod_l_factorize(A, L, &c);
            samples[r] = now_s() - t0;
        }
        double err = solve_error(A, L, &c);
        double stored = 0.0, sflops = 0.0;
        if (L->is_super) supernodal_size(L, &stored, &sflops);
        else {
            stored = lnz;
            sflops = fl;
        }
        double sum = 0.0;
        for (int r = 0; r < o->reps; r++) sum += samples[r];
        qsort(samples, (size_t)o->reps, sizeof(double), cmp_double);
        double median = o->reps % 2 ? samples[o->reps / 2]
                                    : 0.5 * (samples[o->reps / 2 - 1] + samples[o->reps / 2]);
        printf("result ordering=%s mode=%s threads=%d reps=%d median_s=%.6f min_s=%.6f "
               "max_s=%.6f mean_s=%.6f analyse_s=%.6f lnz=%.0f fl=%.6e stored=%.0f "
               "stored_flops=%.6e nsuper=%zu is_super=%d max_err=%.3e\n",
               used, mode, threads, o->reps, median, samples[0], samples[o->reps - 1],
               sum / o->reps, analyse_s, lnz, fl, stored, sflops, L->is_super ? L->nsuper : 0,
               L->is_super, err);
        fflush(stdout);
    }
    free(samples);
    cholmod_l_free_factor(&L, &c);
    cholmod_l_finish(&c);
}

int main(int argc, char **argv) {
    options o = parse_options(argc, argv);
    matrix_file m = read_matrix(o.path);

    cholmod_common c;
    cholmod_l_start(&c);
    c.print = 0;
    cholmod_sparse *A = cholmod_l_allocate_sparse((size_t)m.n, (size_t)m.n, (size_t)m.nnz,
                                                  1, 1, 1, CHOLMOD_REAL, &c);
    if (!A) die("cannot allocate the CHOLMOD matrix");
    memcpy(A->p, m.col_ptr, sizeof(int64_t) * (size_t)(m.n + 1));
    memcpy(A->i, m.row_idx, sizeof(int64_t) * (size_t)m.nnz);
    memcpy(A->x, m.values, sizeof(double) * (size_t)m.nnz);
    if (!cholmod_l_check_sparse(A, &c)) die("invalid matrix");

    int version[3];
    cholmod_l_version(version);
    printf("info cholmod=%d.%d.%d n=%lld nnz=%lld blas=\"%s\"\n", version[0], version[1],
           version[2], (long long)m.n, (long long)m.nnz, blas_name());
    fflush(stdout);

    for (int oi = 0; oi < o.n_orderings; oi++)
        for (int mi = 0; mi < o.n_modes; mi++)
            run_configuration(&o, &m, A, o.orderings[oi], o.modes[mi]);

    cholmod_l_free_sparse(&A, &c);
    cholmod_l_finish(&c);
    free(m.col_ptr);
    free(m.row_idx);
    free(m.values);
    free(m.perm);
    return 0;
}
