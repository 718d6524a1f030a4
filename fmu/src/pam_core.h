/* pamsim muscle model: the FMI-independent core.
 *
 * Equations, event indicators and stick/slip mode logic of pamsim.model and
 * pamsim.simulator, and a Dormand-Prince 5(4) integrator with dense output
 * and event location for co-simulation.  The FMI 2.0 and 3.0 wrappers only
 * translate calls into this API.
 *
 * All variables live in r[] (reals) and i[] (integers), indexed by the
 * R_* / I_* constants of the generated pam_variables.h.  SI units throughout;
 * the paper's polynomials take pressure in bar and convert at their edge.
 */
#ifndef PAM_CORE_H
#define PAM_CORE_H

#include <stdint.h>
#include "pam_variables.h"
#include "pam_shared.h" /* constants and choices shared with Python, generated */
#include "pam_log.h"

/* Only the FMI functions leave the shared library (also when it is rebuilt by fmpy or cmake
 * without -fvisibility=hidden). */
#if defined(__GNUC__)
#pragma GCC visibility push(hidden)
#endif

/* Called by pam_do_step at each located event that changed the mode or the states: the time, the
 * mode before and after, and the states just before and just after the jump (NULL for the FMU). */
/* Called by pam_do_step for each accepted step from t0_s to t1_s, before any event at t1_s: y0 and
 * the step's stages (the dense output of pam_core.c on [t0_s, t0_s + h_s]), or NULL stages for a held
 * load whose states stay y0 (NULL for the FMU). */
typedef void (*PamStepFn)(void *env, double t0_s, double t1_s, double h_s, const double *y0, const void *stages);
typedef void (*PamEventFn)(void *env, double t_s, int from_mode, int to_mode, const double *y_before,
                           const double *y_after);

/* A static force table (pamsim.fmu.force_table): (F, F_x, F_p, F_xp) at the nodes of a uniform grid,
 * node (i, j) at index i * np + j.  The FMU's is baked in at build time; the native library passes
 * one per case. */
typedef struct {
    int nx, np;
    double x0, dx, p0, dp;
    const double (*nodes)[4];
} PamTable;

typedef struct PamCore {
    double r[PAM_NR];
    int32_t i[PAM_NI];
    double time_s;
    int mode;
    /* derived at initialisation */
    double braid_b_m, braid_turns, x_low_m, x_high_m;
    int inputs_changed;     /* co-simulation: re-check a held load at the next step */
    double h_s;             /* co-simulation: next internal step */
    long n_steps, n_rhs, n_events;
    PamLogFn log;
    void *log_env;
    PamEventFn on_event;
    void *event_env;
    PamStepFn on_step;
    void *step_env;
    const PamTable *table; /* static_force_model = table; pam_reset points it at the built-in one */
    int table_edge_logged; /* the built-in table's edge has been reached (logged once) */
    double event_time_s;   /* model exchange: the last event, where continuous time starts from */
    unsigned inputs_set;   /* before the end of initialisation: the signals (bit k) whose input the importer set */
    /* Inputs that a driver sets in closed form inside its segments (the native library; NULL in the FMU):
     * inputs_fn writes them into r[] at t_s, inputs_constant_fn says whether they stay as they are. */
    void (*inputs_fn)(void *env, struct PamCore *c, double t_s);
    int (*inputs_constant_fn)(void *env);
    void *inputs_env;
} PamCore;

/* The values a serialized FMU state holds (fmi_shell.c): those of pam_fmu_common.h, then the geometry
 * and stops derived at initialisation and the table edge's note. */
#define PAM_CORE_SERIAL_FIELDS(dir, io, core)                                              \
    do {                                                                                   \
        int32_t edge_ = (core)->table_edge_logged;                                         \
        PAM_COMMON_SERIAL_FIELDS(dir, io, core);                                           \
        dir(io, &(core)->braid_b_m, sizeof(double));                                       \
        dir(io, &(core)->braid_turns, sizeof(double));                                     \
        dir(io, &(core)->x_low_m, sizeof(double));                                         \
        dir(io, &(core)->x_high_m, sizeof(double));                                        \
        dir(io, &edge_, sizeof edge_);                                                     \
        (core)->table_edge_logged = edge_;                                                 \
    } while (0)

#if defined(__GNUC__)
#pragma GCC visibility pop
#endif

#include "pam_fmu_common.h" /* the API the FMI shell calls */

#endif
