/* 5-point Gauss-Legendre quadrature on [0, 1] as polynomials of the step fraction: used by the drivers
 * of the generic engine (pam_engine_batch.c, pam_gcore.c), which integrate the work states over each
 * step's dense output. */
#ifndef PAM_GAUSS_H
#define PAM_GAUSS_H

/* 5-point Gauss-Legendre nodes on [0, 1] (each step's quadrature polynomial). */
#define GL_N 5
static const double GL_NODE[GL_N] = {0.046910077030668004, 0.23076534494715845, 0.5, 0.76923465505284155,
                                     0.953089922969332};

/* A[k][j]: coefficient of phi^(j+1) in the integral from 0 to phi of node k's Lagrange polynomial. */
static void gauss_primitives(double A[GL_N][GL_N]) {
    int k, m, j;
    for (k = 0; k < GL_N; k++) {
        double L[GL_N] = {1.0}; /* L[j]: coefficient of phi^j, built one factor at a time */
        int deg = 0;
        for (m = 0; m < GL_N; m++) {
            double scale;
            if (m == k) continue;
            scale = 1.0 / (GL_NODE[k] - GL_NODE[m]);
            for (j = deg + 1; j >= 0; j--)
                L[j] = ((j > 0 ? L[j - 1] : 0.0) - GL_NODE[m] * (j <= deg ? L[j] : 0.0)) * scale;
            deg++;
        }
        for (j = 0; j < GL_N; j++) A[k][j] = L[j] / (double)(j + 1);
    }
}

#endif
