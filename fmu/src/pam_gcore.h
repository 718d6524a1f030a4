/* The FMU core of a generated assembly: every equation comes from the model pamsim.modeling.cmodel
 * generates (pam_model.c), integrated by the generic engine (pam_engine.c); nothing here is physics.
 *
 * All FMU variables live in r[] (reals) and i[] (integers), indexed as the generated pam_variables.h
 * says; PAM_P_R, PAM_U_R, PAM_STATE_R, PAM_DERIV_R and PAM_Y_R map the model's parameter, input,
 * state, derivative and output vectors onto r[].
 */
#ifndef PAM_GCORE_H
#define PAM_GCORE_H

#include <stdint.h>

#include "pam_log.h"
#include "pam_variables.h"

#if defined(__GNUC__)
#pragma GCC visibility push(hidden)
#endif

typedef struct PamCore {
    double r[PAM_NR];
    int32_t i[PAM_NI];
    double time_s;
    int mode;              /* index of the hybrid component's mode (its value is the output PAM_I_MODE) */
    int inputs_changed;    /* co-simulation: re-decide a held mode at the next step */
    double h_s;            /* co-simulation: next internal step */
    long n_steps, n_rhs, n_events;
    PamLogFn log;
    void *log_env;
    double event_time_s;   /* model exchange: the last event, where continuous time starts from */
    unsigned inputs_set;   /* before the end of initialisation: the signals (bit k) whose input the importer set */
    double hold_until_s;   /* co-simulation: the engine's hold of a slip too small to resolve (pam_engine.h) */
    double since_s;        /* co-simulation: the engine's last event or breakpoint */
    int n_zero;            /* co-simulation: the engine's slips in a row that ended where they began */
    /* co-simulation: the engine's stiff switch (pam_engine.h), carried from one communication step to the
     * next, which would otherwise each test a held model afresh and, shorter than its 15 steps, never switch */
    int32_t stiff, n_stiff, n_nonstiff, n_slow;
    double h_stiff_s;
} PamCore;

/* The values a serialized FMU state holds (fmi_shell.c): those of pam_fmu_common.h, then the engine's hold
 * and its stiff switch. */
#define PAM_CORE_SERIAL_FIELDS(dir, io, core)                 \
    do {                                                      \
        int32_t n_zero_ = (core)->n_zero;                     \
        PAM_COMMON_SERIAL_FIELDS(dir, io, core);              \
        dir(io, &(core)->hold_until_s, sizeof(double));       \
        dir(io, &(core)->since_s, sizeof(double));            \
        dir(io, &n_zero_, sizeof n_zero_);                    \
        (core)->n_zero = n_zero_;                             \
        dir(io, &(core)->stiff, sizeof(int32_t));             \
        dir(io, &(core)->n_stiff, sizeof(int32_t));           \
        dir(io, &(core)->n_nonstiff, sizeof(int32_t));        \
        dir(io, &(core)->n_slow, sizeof(int32_t));            \
        dir(io, &(core)->h_stiff_s, sizeof(double));          \
    } while (0)

#if defined(__GNUC__)
#pragma GCC visibility pop
#endif

#include "pam_fmu_common.h" /* the API the FMI shell calls */

#endif
