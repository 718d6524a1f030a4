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

/* Only the FMI functions leave the shared library (also when it is rebuilt by fmpy or cmake
 * without -fvisibility=hidden). */
#if defined(__GNUC__)
#pragma GCC visibility push(hidden)
#endif

enum { PAM_LOG_INFO = 0, PAM_LOG_WARNING = 1, PAM_LOG_ERROR = 2 };

typedef void (*PamLogFn)(void *env, int level, const char *message);
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
} PamCore;

void pam_reset(PamCore *c);
/* Rejects a value (NaN, negative mass, pressure above rating, ...) with a logged message: returns -1. */
int pam_check_value(PamCore *c, unsigned vr, double value);
int pam_check_parameters(PamCore *c);
/* Initial state from the parameters: load at rest, chamber at initial_pressure_gauge_Pa. */
void pam_initialize(PamCore *c);
/* Derivatives, outputs and event indicators from the states, inputs and mode. */
void pam_evaluate(PamCore *c);
/* Reports once (a warning) a state outside the built-in force table, whose edge value the static force
 * then takes: at each solution point (an accepted step, an event), not at an integrator's trial points. */
void pam_note_table_edge(PamCore *c);
/* Model-exchange event update: apply one mode transition; returns 1 if x or v jumped. */
int pam_event_update(PamCore *c);
/* Co-simulation: integrate to t_end, the inputs held or following their signals; 0 on success, -1 on
 * failure (logged), which leaves time_s, the states, the mode and the outputs at the last instant reached. */
int pam_do_step(PamCore *c, double t_end);
/* Directional derivative d(unknowns)/d(knowns) * seed: a central difference per known, mode held;
 * `initializing`: the states, geometry and stops derived again from the parameters on each side. */
int pam_directional_derivative(PamCore *c, const unsigned *unknowns, int n_unknowns, const unsigned *knowns,
                               int n_knowns, const double *seed, double *sensitivity, int initializing);
void pam_logf(PamCore *c, int level, const char *fmt, ...);
/* With input_source = scenario, the inputs follow the signals the FMU was built with (PAM_SIGNALS of
 * pam_variables.h); otherwise these do nothing.  pam_inputs_at sets them at t_s, their values from the
 * left of t_s (left != 0: the end of an interval) or from the right (an event, a start). */
void pam_inputs_at(PamCore *c, double t_s, int left);
/* 1 if input `vr` follows a signal, its value now (from the right) in *value; else 0. */
int pam_input_scheduled(const PamCore *c, unsigned vr, double *value);
/* Before the end of initialisation the importer may still choose input_source: an input it sets is
 * marked here, keeps its value, and is checked against its signal by pam_check_parameters. */
void pam_mark_input_set(PamCore *c, unsigned vr);
/* The first breakpoint (knot, step, a lag's start) of the signals after t_s, or HUGE_VAL if none. */
double pam_next_breakpoint(const PamCore *c, double t_s);

#if defined(__GNUC__)
#pragma GCC visibility pop
#endif

#endif
