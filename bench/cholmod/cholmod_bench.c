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
 * simplicial) the matrix is analysed once. For the METIS ordering the driver also reports
 * which mode CHOLMOD's default (CHOLMOD_AUTO) selects. Then:
 *
 * - batch mode (default): cholmod_l_factorize is timed over --reps repetitions after one
 *   warm-up call (kept as the first sample when it takes more than 2 s), for every
 *   requested BLAS thread count (simplicial: first thread count only, as it does not use
 *   the BLAS), and one line per configuration and thread count is printed:
 *     result ordering=metis mode=supernodal analyse_s=... threads=1 median_s=... ...
 * - --serve: the driver answers single-factorisation requests on stdin (see run_serve),
 *   so that bench_core can alternate CHOLMOD and faer runs under the same machine load.
 *
 * Usage: cholmod_bench FILE [--reps N] [--threads 1,2] [--orderings metis,given]
 *                           [--modes supernodal,simplicial] [--simplicial-max-gflop X]
 *                           [--serve]
 *
 * Diagnostic mode: cholmod_bench --dense N [--reps R] [--threads 1,2] times the BLAS/LAPACK
 * that CHOLMOD uses on a dense N×N Cholesky (dpotrf) and product (dgemm), on the matrix
 * that bench_core's --dense option gives to faer.
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
    int dense;
    int serve;
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
        } else if (strcmp(a, "--serve") == 0) {
            o.serve = 1;
        } else if (strcmp(a, "--dense") == 0 && v) {
            o.dense = atoi(v);
            i++;
        } else if (a[0] != '-' && !o.path) {
            o.path = a;
        } else {
            die("usage: cholmod_bench FILE [--reps N] [--threads 1,2] "
                "[--orderings metis,given,nesdis,amd] [--modes supernodal,simplicial] "
                "[--simplicial-max-gflop X] [--serve]\n"
                "       cholmod_bench --dense N [--reps N] [--threads 1,2]");
        }
    }
    if (!o.path && o.dense <= 0) die("missing matrix file");
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

/* One analysed (ordering, mode) configuration. */
typedef struct {
    char ordering[16]; /* the ordering CHOLMOD actually used */
    char mode[16];
    int supernodal;
    cholmod_common c;
    cholmod_factor *L;
    double analyse_s, lnz, fl, stored, stored_flops;
} config;

/* Analyses A for one configuration; returns 0 (after printing why) when it is skipped or
 * fails. */
static int analyse_config(config *cf, const options *o, const matrix_file *m,
                          cholmod_sparse *A, const char *ordering, const char *mode) {
    memset(cf, 0, sizeof *cf);
    int wanted = ordering_code(ordering);
    cf->supernodal = strcmp(mode, "supernodal") == 0;
    if (!cf->supernodal && strcmp(mode, "simplicial") != 0) die("unknown mode");
    snprintf(cf->mode, sizeof cf->mode, "%s", mode);
    if (wanted == CHOLMOD_GIVEN && !m->perm) {
        printf("skipped ordering=given mode=%s reason=no_permutation_in_file\n", mode);
        return 0;
    }

    cholmod_common *c = &cf->c;
    cholmod_l_start(c);
    c->print = 0;
    c->nmethods = 1;
    c->method[0].ordering = wanted;
    c->postorder = 1;
    c->supernodal = cf->supernodal ? CHOLMOD_SUPERNODAL : CHOLMOD_SIMPLICIAL;
    c->final_ll = 1;

    int64_t *perm = wanted == CHOLMOD_GIVEN ? m->perm : NULL;
    double t0 = now_s();
    cf->L = cholmod_l_analyze_p(A, perm, NULL, 0, c);
    cf->analyse_s = now_s() - t0;
    if (!cf->L && wanted == CHOLMOD_METIS && c->status == CHOLMOD_NOT_INSTALLED) {
        printf("note metis_unavailable=1 fallback=amd\n");
        c->status = CHOLMOD_OK;
        c->method[0].ordering = CHOLMOD_AMD;
        t0 = now_s();
        cf->L = cholmod_l_analyze_p(A, NULL, NULL, 0, c);
        cf->analyse_s = now_s() - t0;
    }
    if (!cf->L || c->status < CHOLMOD_OK) {
        printf("failed ordering=%s mode=%s stage=analyse status=%d\n", ordering, mode, c->status);
        if (cf->L) cholmod_l_free_factor(&cf->L, c);
        cholmod_l_finish(c);
        return 0;
    }
    snprintf(cf->ordering, sizeof cf->ordering, "%s", ordering_label(cf->L->ordering));
    cf->lnz = c->lnz;
    cf->fl = c->fl;
    if (cf->L->is_super) {
        supernodal_size(cf->L, &cf->stored, &cf->stored_flops);
    } else {
        cf->stored = cf->lnz;
        cf->stored_flops = cf->fl;
    }

    if (!cf->supernodal && cf->fl > o->simplicial_max_gflop * 1e9) {
        printf("skipped ordering=%s mode=simplicial reason=flops_%.3g_above_limit\n",
               cf->ordering, cf->fl);
        cholmod_l_free_factor(&cf->L, c);
        cholmod_l_finish(c);
        return 0;
    }

    if (cf->supernodal && wanted != CHOLMOD_GIVEN) {
        /* What CHOLMOD's default (CHOLMOD_AUTO) would choose with this ordering. */
        cholmod_common a;
        cholmod_l_start(&a);
        a.print = 0;
        a.nmethods = 1;
        a.method[0].ordering = c->method[0].ordering;
        cholmod_factor *La = cholmod_l_analyze(A, &a);
        if (La) {
            printf("note ordering=%s auto_mode=%s flops_per_lnz=%.1f supernodal_switch=%.0f\n",
                   ordering_label(La->ordering), La->is_super ? "supernodal" : "simplicial",
                   a.fl / a.lnz, a.supernodal_switch);
            cholmod_l_free_factor(&La, &a);
        }
        cholmod_l_finish(&a);
    }
    return 1;
}

static void free_config(config *cf) {
    if (cf->L) cholmod_l_free_factor(&cf->L, &cf->c);
    cholmod_l_finish(&cf->c);
}

/* One numeric factorisation; returns its duration [s], or a negative value on failure. */
static double factorize_once(config *cf, cholmod_sparse *A) {
    double t0 = now_s();
    int ok = cholmod_l_factorize(A, cf->L, &cf->c);
    double t = now_s() - t0;
    if (!ok || cf->c.status != CHOLMOD_OK || cf->L->minor < A->nrow) return -1.0;
    return t;
}

static void print_config(const config *cf, const char *prefix) {
    printf("%s ordering=%s mode=%s analyse_s=%.6f lnz=%.0f fl=%.6e stored=%.0f "
           "stored_flops=%.6e nsuper=%zu",
           prefix, cf->ordering, cf->mode, cf->analyse_s, cf->lnz, cf->fl, cf->stored,
           cf->stored_flops, cf->L->is_super ? cf->L->nsuper : (size_t)0);
}

/* Batch mode: warm-up and --reps timed factorisations per thread count. */
static void run_batch(const options *o, const matrix_file *m, cholmod_sparse *A) {
    double *samples = malloc(sizeof(double) * (size_t)o->reps);
    if (!samples) die("out of memory");
    for (int oi = 0; oi < o->n_orderings; oi++)
        for (int mi = 0; mi < o->n_modes; mi++) {
            config cf;
            if (!analyse_config(&cf, o, m, A, o->orderings[oi], o->modes[mi])) continue;
            /* The simplicial factorisation does not call the BLAS: one thread count. */
            int n_threads = cf.supernodal ? o->n_threads : 1;
            for (int ti = 0; ti < n_threads; ti++) {
                int threads = o->threads[ti];
                if (!set_threads(threads) && threads > 1) {
                    printf("skipped ordering=%s mode=%s threads=%d "
                           "reason=blas_threads_not_controllable\n",
                           cf.ordering, cf.mode, threads);
                    continue;
                }
                double first = factorize_once(&cf, A);
                if (first < 0.0) {
                    printf("failed ordering=%s mode=%s stage=factorize status=%d\n", cf.ordering,
                           cf.mode, cf.c.status);
                    break;
                }
                int r0 = 0;
                if (first > LONG_RUN_S) samples[r0++] = first;
                for (int r = r0; r < o->reps; r++) samples[r] = factorize_once(&cf, A);
                double err = solve_error(A, cf.L, &cf.c);
                qsort(samples, (size_t)o->reps, sizeof(double), cmp_double);
                double median = o->reps % 2 ? samples[o->reps / 2]
                                            : 0.5 * (samples[o->reps / 2 - 1] +
                                                     samples[o->reps / 2]);
                print_config(&cf, "result");
                printf(" threads=%d reps=%d median_s=%.6f min_s=%.6f max_s=%.6f max_err=%.3e\n",
                       threads, o->reps, median, samples[0], samples[o->reps - 1], err);
                fflush(stdout);
            }
            free_config(&cf);
        }
    free(samples);
}

/* Serve mode: analyse every configuration, print one "config id=K ..." line each and
 * "ready", then answer requests read from stdin, one per line:
 *   factorize K T   ->  "time id=K threads=T s=..."      (one numeric factorisation)
 *   check K         ->  "check id=K max_err=..."         (solve with a known solution)
 *   quit
 * so that the caller can interleave these factorisations with its own. */
static void run_serve(const options *o, const matrix_file *m, cholmod_sparse *A) {
    config *configs = calloc((size_t)(o->n_orderings * o->n_modes), sizeof(config));
    if (!configs) die("out of memory");
    int count = 0;
    for (int oi = 0; oi < o->n_orderings; oi++)
        for (int mi = 0; mi < o->n_modes; mi++)
            if (analyse_config(&configs[count], o, m, A, o->orderings[oi], o->modes[mi])) {
                char prefix[32];
                snprintf(prefix, sizeof prefix, "config id=%d", count);
                print_config(&configs[count], prefix);
                printf("\n");
                count++;
            }
    printf("ready\n");
    fflush(stdout);

    char line[256];
    while (fgets(line, sizeof line, stdin)) {
        int id = -1, threads = 1;
        if (strncmp(line, "quit", 4) == 0) break;
        if (sscanf(line, "factorize %d %d", &id, &threads) == 2) {
            if (id < 0 || id >= count) {
                printf("error reason=bad_id\n");
            } else if (!set_threads(threads) && threads > 1) {
                printf("error reason=blas_threads_not_controllable\n");
            } else {
                double t = factorize_once(&configs[id], A);
                if (t < 0.0)
                    printf("error reason=factorize_failed status=%d\n", configs[id].c.status);
                else
                    printf("time id=%d threads=%d s=%.6f\n", id, threads, t);
            }
        } else if (sscanf(line, "check %d", &id) == 1 && id >= 0 && id < count) {
            printf("check id=%d max_err=%.3e\n", id,
                   solve_error(A, configs[id].L, &configs[id].c));
        } else {
            printf("error reason=bad_request\n");
        }
        fflush(stdout);
    }
    for (int k = 0; k < count; k++) free_config(&configs[k]);
    free(configs);
}

void dpotrf_(const char *uplo, const int *n, double *a, const int *lda, int *info,
             size_t uplo_len);
void dgemm_(const char *transa, const char *transb, const int *m, const int *n, const int *k,
            const double *alpha, const double *a, const int *lda, const double *b,
            const int *ldb, const double *beta, double *c, const int *ldc, size_t transa_len,
            size_t transb_len);

static double median_of(double *v, int count) {
    qsort(v, (size_t)count, sizeof(double), cmp_double);
    return count % 2 ? v[count / 2] : 0.5 * (v[count / 2 - 1] + v[count / 2]);
}

/* Dense SPD matrix, column major: a_ij = ((7 min + 13 max) mod 17)/17 off the diagonal,
 * a_ii = n. */
static void fill_dense(double *a, int n) {
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            int lo = i < j ? i : j, hi = i < j ? j : i;
            a[(size_t)j * n + i] = i == j ? (double)n : (double)((7 * lo + 13 * hi) % 17) / 17.0;
        }
}

static void run_dense(const options *o) {
    int n = o->dense;
    size_t len = (size_t)n * (size_t)n;
    double *a = malloc(sizeof(double) * len), *w = malloc(sizeof(double) * len);
    double *c = malloc(sizeof(double) * len);
    double *potrf = malloc(sizeof(double) * (size_t)o->reps);
    double *gemm = malloc(sizeof(double) * (size_t)o->reps);
    if (!a || !w || !c || !potrf || !gemm) die("out of memory");
    fill_dense(a, n);
    printf("info dense=%d blas=\"%s\"\n", n, blas_name());
    for (int ti = 0; ti < o->n_threads; ti++) {
        int threads = o->threads[ti];
        if (!set_threads(threads) && threads > 1) {
            printf("skipped dense threads=%d reason=blas_threads_not_controllable\n", threads);
            continue;
        }
        int info = 0;
        for (int r = -1; r < o->reps; r++) {
            memcpy(w, a, sizeof(double) * len);
            double t0 = now_s();
            dpotrf_("L", &n, w, &n, &info, 1);
            if (r >= 0) potrf[r] = now_s() - t0;
            if (info != 0) die("dpotrf failed");
        }
        double one = 1.0, zero = 0.0;
        for (int r = -1; r < o->reps; r++) {
            double t0 = now_s();
            dgemm_("N", "N", &n, &n, &n, &one, a, &n, w, &n, &zero, c, &n, 1, 1);
            if (r >= 0) gemm[r] = now_s() - t0;
        }
        printf("dense n=%d threads=%d potrf_median_s=%.6f gemm_median_s=%.6f\n", n, threads,
               median_of(potrf, o->reps), median_of(gemm, o->reps));
        fflush(stdout);
    }
    free(a);
    free(w);
    free(c);
    free(potrf);
    free(gemm);
}

int main(int argc, char **argv) {
    options o = parse_options(argc, argv);
    if (o.dense > 0) {
        run_dense(&o);
        return 0;
    }
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
    printf("info cholmod=%d.%d.%d n=%lld nnz=%lld blas_threads=%d blas=\"%s\"\n", version[0],
           version[1], version[2], (long long)m.n, (long long)m.nnz, set_threads(1),
           blas_name());
    fflush(stdout);

    if (o.serve)
        run_serve(&o, &m, A);
    else
        run_batch(&o, &m, A);

    cholmod_l_free_sparse(&A, &c);
    cholmod_l_finish(&c);
    free(m.col_ptr);
    free(m.row_idx);
    free(m.values);
    free(m.perm);
    return 0;
}
