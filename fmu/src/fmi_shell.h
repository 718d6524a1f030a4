/* The FMI logic that FMI 2.0 and 3.0 share, over the FMU core (pam_gcore.c, named by the generated
 * pam_fmu_core.h).
 *
 * Both wrappers keep their instance as a struct whose first member is an FmuInstance, so a
 * component / instance pointer can be passed here as it is.  Every function takes the name of
 * the FMI function it serves (for error messages) and returns 0 on success and a negative
 * number on error, logged wherever the wrappers logged it before they shared this code (a
 * wrong array length, for one, is not); the wrappers only translate arguments and status codes.
 */
#ifndef FMI_SHELL_H
#define FMI_SHELL_H

#include <stddef.h>
#include <stdint.h>

#include "pam_fmu_core.h"

#if defined(__GNUC__)
#pragma GCC visibility push(hidden)
#endif

/* The state machine of both standards (FMI 2.0 sec. 3.2.3 and 4.2.4, FMI 3.0 sec. 3.2 and 4.2);
 * an FMI 2.0 instance never enters FMU_CONFIG. */
enum {
    FMU_INSTANTIATED = 1 << 0,
    FMU_INIT = 1 << 1,
    FMU_EVENT = 1 << 2,
    FMU_CONT = 1 << 3,
    FMU_STEP = 1 << 4,
    FMU_TERMINATED = 1 << 5,
    FMU_ERROR = 1 << 6,
    FMU_CONFIG = 1 << 7
};
#define FMU_ANY (FMU_INSTANTIATED | FMU_INIT | FMU_EVENT | FMU_CONT | FMU_STEP | FMU_TERMINATED | FMU_ERROR | FMU_CONFIG)
#define FMU_RUNNING (FMU_INIT | FMU_EVENT | FMU_CONT | FMU_STEP | FMU_TERMINATED | FMU_ERROR)

/* What differs between the two standards in the shared logic. */
typedef struct {
    const char *standard;       /* "FMI 2.0", named in state-machine errors */
    const char *real_type;      /* the standard's names of the two variable types, in value-reference errors */
    const char *integer_type;
    const char *differentiable; /* what GetDirectionalDerivative accepts, in its error */
    int time_is_vr0;            /* FMI 3.0 declares time as value reference 0 */
    int enums_are_int64;        /* FMI 3.0 reads and writes Enumerations as Int64, FMI 2.0 as Integer */
    /* The states in which reading the continuous states, or their derivatives and the event
     * indicators, re-evaluates the model (derivatives: the same in both standards). */
    int states_evaluate_in;
    int derivatives_evaluate_in;
} FmuFlavour;

typedef struct {
    PamCore core;
    int state;
    int is_cs;
    int logging_on;
    char *name;
    const FmuFlavour *flavour;
} FmuInstance;

/* Allocates `size` bytes (the wrapper's instance, an FmuInstance first) in FMU_INSTANTIATED,
 * logging through `log` with the instance as environment; NULL if out of memory. */
void *fmu_instantiate(size_t size, const FmuFlavour *flavour, const char *name, int is_cs, int logging_on,
                      PamLogFn log);
void fmu_free(FmuInstance *in);
/* The logger category of a message to pass on, or NULL for an informative one while debug logging is off. */
const char *fmu_log_category(const FmuInstance *in, int level);
/* 1 if `function` may be called in the current state; otherwise 0, logged (if there is an instance). */
int fmu_allowed(FmuInstance *in, const char *function, int states);
/* Logs "function: reason" (there may be no instance) and returns -1. */
int fmu_refuse(FmuInstance *in, const char *function, const char *reason);

int fmu_set_debug_logging(FmuInstance *in, const char *function, int logging_on);
int fmu_setup_experiment(FmuInstance *in, const char *function, int tolerance_defined, double tolerance,
                         double start_time);
int fmu_enter_initialization_mode(FmuInstance *in, const char *function);
int fmu_exit_initialization_mode(FmuInstance *in, const char *function);
int fmu_enter_event_mode(FmuInstance *in, const char *function);
int fmu_enter_continuous_time_mode(FmuInstance *in, const char *function);
int fmu_terminate(FmuInstance *in, const char *function);
int fmu_reset(FmuInstance *in, const char *function);

/* Variables by value reference.  n_values is the length of values (FMI 3.0; FMI 2.0 passes nvr). */
int fmu_get_reals(FmuInstance *in, const char *function, const unsigned vr[], size_t nvr, double values[],
                  size_t n_values);
int fmu_get_integers(FmuInstance *in, const char *function, const unsigned vr[], size_t nvr, int32_t values[],
                     size_t n_values);
int fmu_set_reals(FmuInstance *in, const char *function, const unsigned vr[], size_t nvr, const double values[],
                  size_t n_values);
int fmu_set_integers(FmuInstance *in, const char *function, const unsigned vr[], size_t nvr, const int32_t values[],
                     size_t n_values);
/* Enumerations where they are Int64 (FMI 3.0). */
int fmu_get_enums(FmuInstance *in, const char *function, const unsigned vr[], size_t nvr, int64_t values[],
                  size_t n_values);
int fmu_set_enums(FmuInstance *in, const char *function, const unsigned vr[], size_t nvr, const int64_t values[],
                  size_t n_values);
/* Access to a type the model has none of: fine if empty, else an error saying `what`. */
int fmu_no_such_type(FmuInstance *in, const char *function, int states, size_t nvr, const char *what);

/* FMU state: a copy of the core and the state-machine state, nothing of the importer's. */
int fmu_get_fmu_state(FmuInstance *in, const char *function, void **s);
int fmu_set_fmu_state(FmuInstance *in, const char *function, const void *s);
int fmu_free_fmu_state(FmuInstance *in, const char *function, void **s);
int fmu_serialized_fmu_state_size(FmuInstance *in, const char *function, size_t *size);
int fmu_serialize_fmu_state(FmuInstance *in, const char *function, const void *s, void *bytes, size_t size);
int fmu_deserialize_fmu_state(FmuInstance *in, const char *function, const void *bytes, size_t size, void **s);

int fmu_directional_derivative(FmuInstance *in, const char *function, const unsigned unknowns[], size_t n_unknowns,
                               const unsigned knowns[], size_t n_knowns, const double seed[], size_t n_seed,
                               double sensitivity[], size_t n_sensitivity);

/* Model exchange */
/* next_time: the next time event (a breakpoint of the scenario's signals), if next_time_defined. */
int fmu_update_discrete_states(FmuInstance *in, const char *function, int *states_changed, int *next_time_defined,
                               double *next_time);
int fmu_completed_integrator_step(FmuInstance *in, const char *function);
int fmu_set_time(FmuInstance *in, const char *function, double time);
int fmu_set_continuous_states(FmuInstance *in, const char *function, const double x[], size_t nx);
int fmu_get_continuous_states(FmuInstance *in, const char *function, double x[], size_t nx);
int fmu_get_derivatives(FmuInstance *in, const char *function, double dx[], size_t nx);
int fmu_get_event_indicators(FmuInstance *in, const char *function, double z[], size_t nz);
int fmu_get_nominals(FmuInstance *in, const char *function, double nominals[], size_t nx);

/* Co-simulation.  FMU_STEP_REFUSED (wrong state or no co-simulation instance) and
 * FMU_STEP_REJECTED (a step size that is not a finite number >= 0, or a current communication point
 * that is not the FMU's time) leave the instance as it was; FMU_STEP_FAILED leaves it in FMU_ERROR at
 * the last successful time, with the states, mode and outputs of that instant. */
enum { FMU_STEP_REFUSED = -1, FMU_STEP_REJECTED = -2, FMU_STEP_FAILED = -3 };
int fmu_do_step(FmuInstance *in, const char *function, double current_time, double step_size);

#if defined(__GNUC__)
#pragma GCC visibility pop
#endif

#endif
