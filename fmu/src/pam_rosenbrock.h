/* Rodas4, a stiffly accurate, L-stable Rosenbrock method of order 4 with an embedded method of order 3,
 * six stages and six evaluations of the right-hand side (E. Hairer and G. Wanner, Solving Ordinary
 * Differential Equations II: Stiff and Differential-Algebraic Problems, Springer, 1996; the coefficients
 * in the form of KPP's Rosenbrock integrators: A. Sandu et al., "Benchmarking stiff ODE solvers for
 * atmospheric chemistry problems II: Rosenbrock solvers", Atmospheric Environment 31(20), 1997).  For
 * the autonomous system y' = f(y) with Jacobian J at y0, stage i solves
 *     (I / (h gamma) - J) K_i = f(y0 + sum_j a_ij K_j) + sum_j (c_ij / h) K_j,
 * the step is y1 = y0 + sum_i m_i K_i and its error estimate sum_i e_i K_i (here K_6).  Rodas3, the same
 * form with four stages, took 1475 evaluations of the right-hand side where Rodas4 takes 1259 on the
 * thermal Figure 4 run (benchmarks/bench_chamber.py). */
#ifndef PAM_ROSENBROCK_H
#define PAM_ROSENBROCK_H

typedef struct {
    int stages;
    double gamma;
    double a[6][5], c[6][5]; /* strictly lower triangular: a[i][j], j < i */
    int new_f[6];            /* 0: stage i evaluates f where stage i - 1 did */
    double m[6], e[6];
    double elo;              /* the error estimate's order plus one: the step grows by err^(-1/elo) */
} RosTableau;

static const RosTableau RODAS4 = {
    6, 0.25,
    {{0},
     {1.544},
     {0.9466785280815826, 0.2557011698983284},
     {3.314825187068521, 2.896124015972201, 0.9986419139977817},
     {1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950},
     {1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950, 1.0}},
    {{0},
     {-5.6688},
     {-2.430093356833875, -0.2063599157091915},
     {-0.1073529058151375, -9.594562251023355, -20.47028614809616},
     {7.496443313967647, -10.24680431464352, -33.99990352819905, 11.70890893206160},
     {8.083246795921522, -7.981132988064893, -31.52159432874371, 16.31930543123136, -6.058818238834054}},
    {1, 1, 1, 1, 1, 1},
    {1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950, 1.0, 1.0},
    {0.0, 0.0, 0.0, 0.0, 0.0, 1.0},
    4.0};

/* LU factorisation with partial pivoting of the n x n matrix a (row-major, in place); 0 if singular. */
static int ros_lu(double *a, int *piv, int n) {
    int i, j, k;
    for (k = 0; k < n; k++) {
        int p = k;
        double big = fabs(a[k * n + k]);
        for (i = k + 1; i < n; i++)
            if (fabs(a[i * n + k]) > big) {
                big = fabs(a[i * n + k]);
                p = i;
            }
        if (!(big > 0.0) || !isfinite(big)) return 0;
        piv[k] = p;
        if (p != k)
            for (j = 0; j < n; j++) {
                double t = a[k * n + j];
                a[k * n + j] = a[p * n + j];
                a[p * n + j] = t;
            }
        for (i = k + 1; i < n; i++) {
            double l = a[i * n + k] / a[k * n + k];
            a[i * n + k] = l;
            for (j = k + 1; j < n; j++) a[i * n + j] -= l * a[k * n + j];
        }
    }
    return 1;
}

/* Solves a x = b in place in b, from ros_lu's factors. */
static void ros_solve(const double *a, const int *piv, int n, double *b) {
    int i, j;
    for (i = 0; i < n; i++) {
        double t = b[piv[i]];
        b[piv[i]] = b[i];
        b[i] = t;
        for (j = 0; j < i; j++) b[i] -= a[i * n + j] * b[j];
    }
    for (i = n - 1; i >= 0; i--) {
        for (j = i + 1; j < n; j++) b[i] -= a[i * n + j] * b[j];
        b[i] /= a[i * n + i];
    }
}

#endif
