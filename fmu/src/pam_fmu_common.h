/* What an FMU core needs beside its model (pam_gcore.c, any generated assembly on the generic engine):
 * logging, a variable's range check and the input signals of the scenario the FMU was built from.  The
 * core's header defines PamCore with the fields used here (r[], i[], time_s, inputs_set, log, log_env)
 * and includes this file after it. */
#ifndef PAM_FMU_COMMON_H
#define PAM_FMU_COMMON_H

#include <stddef.h>

#include "pam_fmu_core.h"

#if defined(__GNUC__)
#pragma GCC visibility push(hidden)
#endif

/* ------------------------------------------------ what each core implements, the FMI shell calls */

void pam_reset(PamCore *c);
/* Rejects a value (NaN, out of range, above a rating, ...) with a logged message: returns -1. */
int pam_check_value(PamCore *c, unsigned vr, double value);
int pam_check_parameters(PamCore *c);
/* Initial state from the parameters and inputs, and the mode decided there. */
void pam_initialize(PamCore *c);
/* Derivatives, outputs and event indicators from the states, inputs and mode. */
void pam_evaluate(PamCore *c);
/* Notes what an accepted integrator step reached (the one-muscle core: a state outside its force table). */
void pam_note_table_edge(PamCore *c);
/* Model-exchange event update: apply one mode transition; returns 1 if a state jumped. */
int pam_event_update(PamCore *c);
/* Co-simulation: integrate to t_end, the inputs held or following their signals; 0 on success, -1 on
 * failure (logged), which leaves time_s, the states, the mode and the outputs at the last instant reached. */
int pam_do_step(PamCore *c, double t_end);
/* Directional derivative sum_k seed[k] d(unknowns)/d(knowns[k]), mode held; `initializing`: the states
 * (and whatever else the parameters determine) derived again from the parameters. */
int pam_directional_derivative(PamCore *c, const unsigned *unknowns, int n_unknowns, const unsigned *knowns,
                               int n_knowns, const double *seed, double *sensitivity, int initializing);
/* The reason a deserialized core cannot be this FMU's (a mode it does not have, a non-finite time), or NULL. */
const char *pam_state_invalid(const PamCore *c);
/* Takes the values of `from` (a saved state), keeping this instance's logger, callbacks and tables. */
void pam_adopt_state(PamCore *c, const PamCore *from);

/* The values of a serialized FMU state that both cores hold, written or read in one order by `dir`
 * (fmi_shell.c); each core's PAM_CORE_SERIAL_FIELDS adds its own after these. */
#define PAM_COMMON_SERIAL_FIELDS(dir, io, core)                                            \
    do {                                                                                   \
        int32_t mode_ = (int32_t)(core)->mode, changed_ = (core)->inputs_changed;         \
        int64_t steps_ = (core)->n_steps, rhs_ = (core)->n_rhs, events_ = (core)->n_events; \
        uint32_t set_ = (core)->inputs_set;                                                \
        dir(io, (core)->r, sizeof (core)->r);                                              \
        dir(io, (core)->i, sizeof (core)->i);                                              \
        dir(io, &(core)->time_s, sizeof(double));                                          \
        dir(io, &mode_, sizeof mode_);                                                     \
        dir(io, &changed_, sizeof changed_);                                               \
        dir(io, &(core)->h_s, sizeof(double));                                             \
        dir(io, &steps_, sizeof steps_);                                                   \
        dir(io, &rhs_, sizeof rhs_);                                                       \
        dir(io, &events_, sizeof events_);                                                 \
        dir(io, &(core)->event_time_s, sizeof(double));                                    \
        dir(io, &set_, sizeof set_);                                                       \
        (core)->mode = mode_;                                                              \
        (core)->inputs_changed = changed_;                                                 \
        (core)->n_steps = (long)steps_;                                                    \
        (core)->n_rhs = (long)rhs_;                                                        \
        (core)->n_events = (long)events_;                                                  \
        (core)->inputs_set = set_;                                                         \
    } while (0)

/* ------------------------------------------------ shared (pam_fmu_common.c) */

void pam_logf(PamCore *c, int level, const char *fmt, ...);
/* pamsim.parameters.Parameter.violation: 1 and the reason in `why` if `value` is outside the generated
 * range of `info`, else 0. */
int pam_range_violation(const PamVarInfo *info, double value, char *why, size_t size);
/* A value for variable `vr` that is not finite, or an input's outside its range: -1, logged. */
int pam_check_own_range(PamCore *c, unsigned vr, double value);
/* Every parameter and input finite, and every parameter in its range: else -1, each fault logged. */
int pam_check_parameter_ranges(PamCore *c);

/* With input_source = scenario, the inputs follow the signals the FMU was built with (PAM_SIGNALS of
 * pam_variables.h); otherwise these do nothing.  pam_inputs_at sets them at t_s, their values from the
 * left of t_s (left != 0: the end of an interval) or from the right (an event, a start). */
void pam_inputs_at(PamCore *c, double t_s, int left);
/* The signals on the piece that begins at or before t_piece_s (from the right), its formula continued to t_s
 * however far past the piece's end t_s is (model exchange between two events). */
void pam_inputs_on_piece(PamCore *c, double t_piece_s, double t_s);
/* The same, but for the inputs in `keep` (bit k: signal k), which the importer set and keep their value. */
void pam_apply_signals(PamCore *c, double t_s, int left, unsigned keep);
/* 1 if input `vr` follows a signal, the value the FMU applies now in *value (its signal's at the time, from the
 * right; in model exchange's continuous time the last event's piece); else 0. */
int pam_input_scheduled(const PamCore *c, unsigned vr, double *value);
/* Before the end of initialisation the importer may still choose input_source: an input it sets is
 * marked here, keeps its value, and is checked against its signal by pam_check_signals. */
void pam_mark_input_set(PamCore *c, unsigned vr);
/* The first breakpoint (knot, step, a lag's start) of the signals after t_s, or HUGE_VAL if none. */
double pam_next_breakpoint(const PamCore *c, double t_s);
/* Model exchange's next time event after t_s: the next breakpoint, or the end of a running hold of a slip
 * that ended where it began (pam_event_update), whichever comes first; HUGE_VAL if neither. */
double pam_next_event_time(const PamCore *c, double t_s);
/* 1 if t_s is a breakpoint of the signals. */
int pam_at_breakpoint(const PamCore *c, double t_s);
/* 1 if no input changes from t_s to the next breakpoint. */
int pam_inputs_constant(const PamCore *c, double t_s);
/* input_source = scenario: the FMU has signals, an input the importer set equals its signal, and each
 * signal stays in its input's range at every knot; -1 (logged) if not. */
int pam_check_signals(PamCore *c);

#if defined(__GNUC__)
#pragma GCC visibility pop
#endif

#endif
