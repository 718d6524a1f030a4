/* Benchmark driver: the C core without any FMI layer or importer.
 *
 * Reads cases "mass_kg supply_gauge_Pa valve_open_s duration_s" from stdin,
 * runs each from rest with the valve opening at valve_open_s, stepping the
 * co-simulation integrator with communication step argv[1] [s], and prints
 * the final contraction [m] of each case and the total compute time [s]
 * (clock_gettime around the simulations only). */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "pam_core.h"

#define MAX_CASES 1000

static void log_stderr(void *env, int level, const char *message) {
    (void)env;
    (void)level;
    fprintf(stderr, "%s\n", message);
}

int main(int argc, char **argv) {
    static double mass[MAX_CASES], supply[MAX_CASES], t_open[MAX_CASES], duration[MAX_CASES], x_end[MAX_CASES];
    static PamCore core;
    double dt = argc > 1 ? atof(argv[1]) : 0.1, elapsed;
    int n = 0, k;
    struct timespec t0, t1;
    while (n < MAX_CASES && scanf("%lf %lf %lf %lf", &mass[n], &supply[n], &t_open[n], &duration[n]) == 4) n++;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (k = 0; k < n; k++) {
        double t = 0.0;
        pam_reset(&core);
        core.log = log_stderr;
        core.r[R_load_mass_kg] = mass[k];
        core.r[R_supply_pressure_gauge_Pa] = supply[k];
        core.r[R_valve_command] = 0.0;
        if (pam_check_parameters(&core)) return 2;
        pam_initialize(&core);
        if (pam_do_step(&core, t_open[k])) return 3;
        core.r[R_valve_command] = 1.0;
        core.inputs_changed = 1;
        t = t_open[k];
        while (t < duration[k]) {
            double next = t + dt < duration[k] ? t + dt : duration[k];
            if (pam_do_step(&core, next)) return 3;
            t = next;
        }
        x_end[k] = core.r[R_contraction_m];
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    elapsed = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    for (k = 0; k < n; k++) printf("%.12g\n", x_end[k]);
    printf("elapsed_s %.9g\n", elapsed);
    return 0;
}
