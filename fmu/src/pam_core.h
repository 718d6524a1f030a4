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

/* Only the FMI functions leave the shared library (also when it is rebuilt by fmpy or cmake
 * without -fvisibility=hidden). */
#if defined(__GNUC__)
#pragma GCC visibility push(hidden)
#endif

/* pamsim.model.Mode */
enum { PAM_SLIP_DOWN = -1, PAM_STICK = 0, PAM_SLIP_UP = 1, PAM_STOP_LOW = 2, PAM_STOP_HIGH = 3 };
enum { PAM_LOG_INFO = 0, PAM_LOG_WARNING = 1, PAM_LOG_ERROR = 2 };

typedef void (*PamLogFn)(void *env, int level, const char *message);

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
} PamCore;

void pam_reset(PamCore *c);
/* Rejects a value (NaN, negative mass, pressure above rating, ...) with a logged message: returns -1. */
int pam_check_value(PamCore *c, unsigned vr, double value);
int pam_check_parameters(PamCore *c);
/* Initial state from the parameters: load at rest, chamber at initial_pressure_gauge_Pa. */
void pam_initialize(PamCore *c);
/* Derivatives, outputs and event indicators from the states, inputs and mode. */
void pam_evaluate(PamCore *c);
/* Model-exchange event update: apply one mode transition; returns 1 if x or v jumped. */
int pam_event_update(PamCore *c);
/* Co-simulation: integrate to t_end with the inputs held; 0 on success, -1 on failure (logged), which
 * leaves time_s, the states, the mode and the outputs at the last instant reached. */
int pam_do_step(PamCore *c, double t_end);
/* Directional derivative d(unknowns)/d(knowns) * seed: a central difference per known, mode held. */
int pam_directional_derivative(PamCore *c, const unsigned *unknowns, int n_unknowns, const unsigned *knowns,
                               int n_knowns, const double *seed, double *sensitivity);
void pam_logf(PamCore *c, int level, const char *fmt, ...);

#if defined(__GNUC__)
#pragma GCC visibility pop
#endif

#endif
