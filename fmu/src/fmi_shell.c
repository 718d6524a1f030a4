/* The FMI logic that FMI 2.0 and 3.0 share; see fmi_shell.h. */
#include "fmi_shell.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *level_category[] = {"logStatusOK", "logStatusWarning", "logStatusError"};

void *fmu_instantiate(size_t size, const FmuFlavour *flavour, const char *name, int is_cs, int logging_on,
                      PamLogFn log) {
    FmuInstance *in = (FmuInstance *)calloc(1, size);
    if (!in) return NULL;
    in->name = (char *)malloc(strlen(name) + 1);
    if (in->name) strcpy(in->name, name);
    in->flavour = flavour;
    in->is_cs = is_cs;
    in->logging_on = logging_on;
    pam_reset(&in->core);
    in->core.log = log;
    in->core.log_env = in;
    in->state = FMU_INSTANTIATED;
    return in;
}

void fmu_free(FmuInstance *in) {
    if (!in) return;
    free(in->name);
    free(in);
}

const char *fmu_log_category(const FmuInstance *in, int level) {
    return in->logging_on || level != PAM_LOG_INFO ? level_category[level] : NULL;
}

int fmu_allowed(FmuInstance *in, const char *function, int states) {
    if (!in) return 0;
    if (in->state & states) return 1;
    pam_logf(&in->core, PAM_LOG_ERROR, "%s: not allowed in the current state (%s state machine)", function,
             in->flavour->standard);
    return 0;
}

int fmu_refuse(FmuInstance *in, const char *function, const char *reason) {
    if (in) pam_logf(&in->core, PAM_LOG_ERROR, "%s: %s", function, reason);
    return -1;
}

/* Moves to `to` if `function` is allowed in `from`. */
static int transition(FmuInstance *in, const char *function, int from, int to) {
    if (!fmu_allowed(in, function, from)) return -1;
    in->state = to;
    return 0;
}

int fmu_set_debug_logging(FmuInstance *in, const char *function, int logging_on) {
    if (!fmu_allowed(in, function, FMU_ANY)) return -1;
    in->logging_on = logging_on;
    return 0;
}

int fmu_setup_experiment(FmuInstance *in, const char *function, int tolerance_defined, double tolerance,
                         double start_time) {
    if (!fmu_allowed(in, function, FMU_INSTANTIATED)) return -1;
    in->core.time_s = start_time;
    /* The importer's tolerance tightens the co-simulation integrator, never loosens the default. */
    if (tolerance_defined && tolerance > 0.0 && tolerance < in->core.r[R_cs_relative_tolerance])
        in->core.r[R_cs_relative_tolerance] = tolerance;
    return 0;
}

int fmu_enter_initialization_mode(FmuInstance *in, const char *function) {
    return transition(in, function, FMU_INSTANTIATED, FMU_INIT);
}

/* A breakpoint within a relative 1e-9 of the time is this event's: an importer may take a time event as reached
 * at a point that close to it (fmpy's math.isclose does), and a next event time a few roundings later would have
 * it integrate over nothing (CVode: "tout too close to t0").  The event is then at that breakpoint. */
#define PAM_SAME_INSTANT 1e-9

static double event_instant(const PamCore *c, double t_s) {
    double next = pam_next_breakpoint(c, t_s);
    while (isfinite(next) && next - t_s <= PAM_SAME_INSTANT * fmax(fabs(t_s), fabs(next))) {
        t_s = next;
        next = pam_next_breakpoint(c, t_s);
    }
    return t_s;
}

/* The model-exchange event at the time: at its breakpoint (event_instant), where it sees the signals from
 * the right. */
static void enter_event_instant(FmuInstance *in) {
    in->core.event_time_s = event_instant(&in->core, in->core.time_s);
    pam_inputs_at(&in->core, in->core.event_time_s, 0);
}

int fmu_exit_initialization_mode(FmuInstance *in, const char *function) {
    if (!fmu_allowed(in, function, FMU_INIT)) return -1;
    if (pam_check_parameters(&in->core)) {
        in->state = FMU_ERROR;
        return -1;
    }
    pam_initialize(&in->core);
    in->core.inputs_set = 0; /* input_source is fixed from here: a set input is checked when it is set */
    in->state = in->is_cs ? FMU_STEP : FMU_EVENT;
    if (in->is_cs) in->core.event_time_s = in->core.time_s;
    else enter_event_instant(in);
    return 0;
}

int fmu_enter_event_mode(FmuInstance *in, const char *function) {
    if (!fmu_allowed(in, function, FMU_EVENT | FMU_CONT) || in->is_cs) return -1;
    in->state = FMU_EVENT;
    enter_event_instant(in);
    return 0;
}

int fmu_enter_continuous_time_mode(FmuInstance *in, const char *function) {
    return transition(in, function, FMU_EVENT, FMU_CONT);
}

int fmu_terminate(FmuInstance *in, const char *function) {
    return transition(in, function, FMU_EVENT | FMU_CONT | FMU_STEP, FMU_TERMINATED);
}

int fmu_reset(FmuInstance *in, const char *function) {
    if (!fmu_allowed(in, function, FMU_ANY)) return -1;
    pam_reset(&in->core);
    in->state = FMU_INSTANTIATED;
    return 0;
}

/* ------------------------------------------------------------ variables */

/* Outputs of the initialization mode follow the parameters set so far; invalid ones (and a start
 * outside the force table) are reported once, by ExitInitializationMode, not at every read. */
static void refresh(FmuInstance *in, int evaluate_in) {
    PamLogFn log = in->core.log;
    if (in->state == FMU_INIT) {
        in->core.log = 0;
        if (pam_check_parameters(&in->core) == 0) pam_initialize(&in->core);
        in->core.log = log;
    }
    if (in->state & evaluate_in) pam_evaluate(&in->core);
}

/* kind: 'r' (Real / Float64), 'i' (Integer / Int32; in FMI 2.0 also an Enumeration), 'e' (FMI 3.0 Int64:
 * an Enumeration). */
static int check_vr(FmuInstance *in, const char *function, unsigned vr, char kind) {
    char has = vr >= 1 && vr <= PAM_NVARS ? PAM_VARS[vr - 1].kind : 0;
    if (has == kind || (kind == 'i' && has == 'e' && !in->flavour->enums_are_int64)) return 1;
    pam_logf(&in->core, PAM_LOG_ERROR, "%s: no %s variable with value reference %u", function,
             kind == 'r' ? in->flavour->real_type : kind == 'i' ? in->flavour->integer_type : "Enumeration (Int64)", vr);
    return 0;
}

/* Parameters before the end of initialisation, inputs at any time before termination. */
static int settable(FmuInstance *in, const char *function, unsigned vr) {
    PamCausality cz = PAM_VARS[vr - 1].causality;
    if (cz == PAM_INPUT && (in->state & (FMU_INSTANTIATED | FMU_INIT | FMU_EVENT | FMU_CONT | FMU_STEP))) return 1;
    if (cz == PAM_PARAMETER && (in->state & (FMU_INSTANTIATED | FMU_INIT))) return 1;
    pam_logf(&in->core, PAM_LOG_ERROR, "%s: %s cannot be set %s", function, PAM_VARS[vr - 1].name,
             cz == PAM_PARAMETER ? "after initialization (fixed parameter)" : "(not a parameter or input)");
    return 0;
}

/* Values may be read from the end of instantiation, and are then up to date. */
static int begin_read(FmuInstance *in, const char *function, size_t nvr, size_t n_values) {
    if (!fmu_allowed(in, function, FMU_RUNNING) || n_values != nvr) return -1;
    /* Co-simulation too: an input set at a communication point shows in the outputs at once. */
    refresh(in, FMU_EVENT | FMU_CONT | FMU_STEP);
    return 0;
}

int fmu_get_reals(FmuInstance *in, const char *function, const unsigned vr[], size_t nvr, double values[],
                  size_t n_values) {
    size_t k;
    if (begin_read(in, function, nvr, n_values)) return -1;
    for (k = 0; k < nvr; k++) {
        if (vr[k] == 0 && in->flavour->time_is_vr0) {
            values[k] = in->core.time_s;
            continue;
        }
        if (!check_vr(in, function, vr[k], 'r')) return -1;
        values[k] = in->core.r[PAM_VARS[vr[k] - 1].index];
    }
    return 0;
}

/* Integers and enumerations share i[]: `kind` 'i' reads into values32, 'e' (FMI 3.0 Int64) into values64. */
static int get_ints(FmuInstance *in, const char *function, const unsigned vr[], size_t nvr, size_t n_values, char kind,
                    int32_t values32[], int64_t values64[]) {
    size_t k;
    if (begin_read(in, function, nvr, n_values)) return -1;
    for (k = 0; k < nvr; k++) {
        int32_t value;
        if (!check_vr(in, function, vr[k], kind)) return -1;
        value = in->core.i[PAM_VARS[vr[k] - 1].index];
        if (kind == 'e') values64[k] = value;
        else values32[k] = value;
    }
    return 0;
}

int fmu_get_integers(FmuInstance *in, const char *function, const unsigned vr[], size_t nvr, int32_t values[],
                     size_t n_values) {
    return get_ints(in, function, vr, nvr, n_values, 'i', values, NULL);
}

int fmu_get_enums(FmuInstance *in, const char *function, const unsigned vr[], size_t nvr, int64_t values[],
                  size_t n_values) {
    return get_ints(in, function, vr, nvr, n_values, 'e', NULL, values);
}

int fmu_set_reals(FmuInstance *in, const char *function, const unsigned vr[], size_t nvr, const double values[],
                  size_t n_values) {
    size_t k;
    if (!fmu_allowed(in, function, FMU_INSTANTIATED | FMU_INIT | FMU_EVENT | FMU_CONT | FMU_STEP) || n_values != nvr)
        return -1;
    for (k = 0; k < nvr; k++) {
        double *dst, scheduled;
        if (!check_vr(in, function, vr[k], 'r') || !settable(in, function, vr[k])) return -1;
        if (in->state & (FMU_INSTANTIATED | FMU_INIT)) pam_mark_input_set(&in->core, vr[k]);
        else if (pam_input_scheduled(&in->core, vr[k], &scheduled) && values[k] != scheduled) {
            /* Echoing the signal's value is harmless; driving an input the FMU overrides would be ignored. */
            pam_logf(&in->core, PAM_LOG_ERROR, "%s: %s = %g: this FMU's inputs follow the signals of the scenario "
                     "it was built from (input_source = scenario; %g at t = %g s); set input_source = importer (0) "
                     "to drive them", function, PAM_VARS[vr[k] - 1].name, values[k], scheduled, in->core.time_s);
            return -1;
        }
        if (pam_check_value(&in->core, vr[k], values[k])) return -1;
        dst = &in->core.r[PAM_VARS[vr[k] - 1].index];
        if (*dst != values[k]) in->core.inputs_changed = 1;
        *dst = values[k];
    }
    return 0;
}

static int set_ints(FmuInstance *in, const char *function, const unsigned vr[], size_t nvr, size_t n_values, char kind,
                    const int32_t values32[], const int64_t values64[]) {
    size_t k;
    if (!fmu_allowed(in, function, FMU_INSTANTIATED | FMU_INIT) || n_values != nvr) return -1;
    for (k = 0; k < nvr; k++) {
        int64_t value = kind == 'e' ? values64[k] : values32[k];
        if (!check_vr(in, function, vr[k], kind) || !settable(in, function, vr[k])) return -1;
        /* Beyond int32 is beyond every choice's range: clamped, it stays out of range for the parameter check. */
        in->core.i[PAM_VARS[vr[k] - 1].index] = value > INT32_MAX ? INT32_MAX
                                                : value < INT32_MIN ? INT32_MIN : (int32_t)value;
    }
    return 0;
}

int fmu_set_integers(FmuInstance *in, const char *function, const unsigned vr[], size_t nvr, const int32_t values[],
                     size_t n_values) {
    return set_ints(in, function, vr, nvr, n_values, 'i', values, NULL);
}

int fmu_set_enums(FmuInstance *in, const char *function, const unsigned vr[], size_t nvr, const int64_t values[],
                  size_t n_values) {
    return set_ints(in, function, vr, nvr, n_values, 'e', NULL, values);
}

int fmu_no_such_type(FmuInstance *in, const char *function, int states, size_t nvr, const char *what) {
    if (!fmu_allowed(in, function, states)) return -1;
    if (nvr == 0) return 0;
    pam_logf(&in->core, PAM_LOG_ERROR, "%s: %s", function, what);
    return -1;
}

/* ------------------------------------------------------------ FMU state */

typedef struct {
    PamCore core;
    int state;
} Snapshot;

/* The serialized form: values only, never an address (a state may be loaded in another process,
 * where the instance's table, logger and callbacks live elsewhere):
 *   "PAMSTATE" | format version | this build's token | the values, in a fixed order | FNV-1a 64 checksum
 * of everything before it.  A state is for the build that wrote it (the token), whose layout of r[]
 * and i[] it shares. */
static const char SERIAL_MAGIC[8] = {'P', 'A', 'M', 'S', 'T', 'A', 'T', 'E'};
#define SERIAL_VERSION 4u

typedef struct {
    unsigned char *bytes; /* NULL: only count */
    size_t at;
} Writer;

static void put(Writer *w, const void *value, size_t size) {
    if (w->bytes) memcpy(w->bytes + w->at, value, size);
    w->at += size;
}

typedef struct {
    const unsigned char *bytes;
    size_t at, size;
} Reader;

static void take(Reader *r, void *value, size_t size) {
    if (r->at + size <= r->size) memcpy(value, r->bytes + r->at, size);
    r->at += size;
}

/* Each field the state holds, written or read in one order; `dir` is put or take: the core's
 * (PAM_CORE_SERIAL_FIELDS of its header), then the state-machine state. */
#define SERIAL_FIELDS(dir, io, snap)                          \
    do {                                                      \
        int32_t state_ = (snap)->state;                       \
        PAM_CORE_SERIAL_FIELDS(dir, io, &(snap)->core);       \
        dir(io, &state_, sizeof state_);                      \
        (snap)->state = state_;                               \
    } while (0)

static uint64_t fnv1a64(const unsigned char *bytes, size_t size) {
    uint64_t h = 14695981039346656037ull;
    size_t k;
    for (k = 0; k < size; k++) {
        h ^= bytes[k];
        h *= 1099511628211ull;
    }
    return h;
}

static size_t serial_size(void) {
    Snapshot dummy;
    Writer w = {NULL, 0};
    uint32_t version = SERIAL_VERSION;
    memset(&dummy, 0, sizeof dummy);
    put(&w, SERIAL_MAGIC, sizeof SERIAL_MAGIC);
    put(&w, &version, sizeof version);
    put(&w, PAM_TOKEN, sizeof(PAM_TOKEN));
    SERIAL_FIELDS(put, &w, &dummy);
    return w.at + sizeof(uint64_t);
}

/* A state the caller had from before is reused, as the standards allow. */
static Snapshot *snapshot_for(void **s) {
    return *s ? (Snapshot *)*s : (Snapshot *)calloc(1, sizeof(Snapshot));
}

int fmu_get_fmu_state(FmuInstance *in, const char *function, void **s) {
    Snapshot *copy;
    if (!fmu_allowed(in, function, FMU_ANY)) return -1;
    copy = snapshot_for(s);
    if (!copy) return -1;
    copy->core = in->core;
    copy->state = in->state;
    *s = copy;
    return 0;
}

int fmu_set_fmu_state(FmuInstance *in, const char *function, const void *s) {
    if (!fmu_allowed(in, function, FMU_ANY) || !s) return -1;
    /* The values are the state's; the table, the logger and the callbacks are this instance's. */
    pam_adopt_state(&in->core, &((const Snapshot *)s)->core);
    in->state = ((const Snapshot *)s)->state;
    return 0;
}

int fmu_free_fmu_state(FmuInstance *in, const char *function, void **s) {
    if (!fmu_allowed(in, function, FMU_ANY)) return -1;
    if (s && *s) {
        free(*s);
        *s = NULL;
    }
    return 0;
}

int fmu_serialized_fmu_state_size(FmuInstance *in, const char *function, size_t *size) {
    if (!fmu_allowed(in, function, FMU_ANY)) return -1;
    *size = serial_size();
    return 0;
}

int fmu_serialize_fmu_state(FmuInstance *in, const char *function, const void *s, void *bytes, size_t size) {
    Snapshot copy;
    Writer w;
    uint32_t version = SERIAL_VERSION;
    uint64_t sum;
    if (!fmu_allowed(in, function, FMU_ANY) || !s) return -1;
    if (size < serial_size()) return fmu_refuse(in, function, "the buffer is smaller than SerializedFMUstateSize");
    copy = *(const Snapshot *)s;
    w.bytes = (unsigned char *)bytes;
    w.at = 0;
    put(&w, SERIAL_MAGIC, sizeof SERIAL_MAGIC);
    put(&w, &version, sizeof version);
    put(&w, PAM_TOKEN, sizeof(PAM_TOKEN));
    SERIAL_FIELDS(put, &w, &copy);
    sum = fnv1a64(w.bytes, w.at);
    put(&w, &sum, sizeof sum);
    return 0;
}

/* The reason a deserialized state cannot be this FMU's, or NULL. */
static const char *invalid_state(const Snapshot *snap) {
    int known = snap->state > 0 && (snap->state & FMU_ANY) == snap->state && (snap->state & (snap->state - 1)) == 0;
    if (!known) return "its state-machine state is not one of this FMU's";
    return pam_state_invalid(&snap->core);
}

int fmu_deserialize_fmu_state(FmuInstance *in, const char *function, const void *bytes, size_t size, void **s) {
    Snapshot read, *copy;
    Reader r;
    uint32_t version = 0;
    uint64_t sum = 0;
    char magic[sizeof SERIAL_MAGIC];
    char token[sizeof(PAM_TOKEN)];
    const char *why;
    if (!fmu_allowed(in, function, FMU_ANY)) return -1;
    if (!bytes || size != serial_size())
        return fmu_refuse(in, function, "the bytes are not a state of this FMU build (wrong size)");
    memset(&read, 0, sizeof read);
    r.bytes = (const unsigned char *)bytes;
    r.at = 0;
    r.size = size;
    take(&r, magic, sizeof magic);
    take(&r, &version, sizeof version);
    take(&r, token, sizeof token);
    if (memcmp(magic, SERIAL_MAGIC, sizeof magic) != 0 || version != SERIAL_VERSION)
        return fmu_refuse(in, function, "the bytes are not a pamsim FMU state of this format version");
    if (memcmp(token, PAM_TOKEN, sizeof token) != 0)
        return fmu_refuse(in, function, "the bytes are a state of another build of this FMU");
    SERIAL_FIELDS(take, &r, &read);
    take(&r, &sum, sizeof sum);
    if (sum != fnv1a64(r.bytes, size - sizeof sum))
        return fmu_refuse(in, function, "the state's checksum does not match: the bytes were changed");
    why = invalid_state(&read);
    if (why) {
        pam_logf(&in->core, PAM_LOG_ERROR, "%s: the state cannot be this FMU's: %s", function, why);
        return -1;
    }
    copy = snapshot_for(s);
    if (!copy) return -1;
    *copy = read; /* no address: fmu_set_fmu_state gives it this instance's */
    *s = copy;
    return 0;
}

int fmu_directional_derivative(FmuInstance *in, const char *function, const unsigned unknowns[], size_t n_unknowns,
                               const unsigned knowns[], size_t n_knowns, const double seed[], size_t n_seed,
                               double sensitivity[], size_t n_sensitivity) {
    if (!fmu_allowed(in, function, FMU_INIT | FMU_EVENT | FMU_CONT | FMU_STEP | FMU_TERMINATED)) return -1;
    if (n_seed != n_knowns || n_sensitivity != n_unknowns
        || pam_directional_derivative(&in->core, unknowns, (int)n_unknowns, knowns, (int)n_knowns, seed,
                                      sensitivity, in->state == FMU_INIT)) {
        pam_logf(&in->core, PAM_LOG_ERROR, "%s: only %s can be differentiated", function, in->flavour->differentiable);
        return -1;
    }
    return 0;
}

/* ------------------------------------------------------------ Model Exchange */

int fmu_update_discrete_states(FmuInstance *in, const char *function, int *states_changed, int *next_time_defined,
                               double *next_time) {
    if (!fmu_allowed(in, function, FMU_EVENT)) return -1;
    *states_changed = pam_event_update(&in->core);
    /* The signals' breakpoints and a hold's end are time events: a held load is checked again there, as in
     * co-simulation. */
    *next_time = pam_next_event_time(&in->core, fmax(in->core.time_s, in->core.event_time_s));
    *next_time_defined = isfinite(*next_time);
    if (!*next_time_defined) *next_time = 0.0;
    return 0;
}

int fmu_completed_integrator_step(FmuInstance *in, const char *function) {
    if (!fmu_allowed(in, function, FMU_CONT)) return -1;
    pam_note_table_edge(&in->core);
    return 0;
}

int fmu_set_time(FmuInstance *in, const char *function, double time) {
    if (!fmu_allowed(in, function, FMU_EVENT | FMU_CONT)) return -1;
    in->core.time_s = time;
    /* An event sees the signals from the right of its breakpoint (a few roundings after the time, see
     * event_instant).  Continuous time from it follows the piece it began, continued past the next time
     * event until that event is handled: an integrator that steps past the event before it stops there
     * (CVode does, and interpolates back) meets no jump, as the continuous equations have none. */
    if (in->state == FMU_EVENT) enter_event_instant(in);
    else pam_inputs_on_piece(&in->core, in->core.event_time_s, fmax(time, in->core.event_time_s));
    return 0;
}

int fmu_set_continuous_states(FmuInstance *in, const char *function, const double x[], size_t nx) {
    size_t k;
    if (!fmu_allowed(in, function, FMU_CONT) || nx != PAM_NX) return -1;
    for (k = 0; k < nx; k++) {
        if (!isfinite(x[k])) {
            pam_logf(&in->core, PAM_LOG_ERROR, "%s: state %u is not finite", function, (unsigned)k);
            return -1;
        }
        in->core.r[PAM_STATE_R[k]] = x[k];
    }
    return 0;
}

/* Copies n reals from the r[] indices `from` after bringing them up to date. */
static int get_vector(FmuInstance *in, const char *function, const int from[], double out[], size_t n, size_t n_expected,
                      int evaluate_in) {
    size_t k;
    if (!fmu_allowed(in, function, FMU_INIT | FMU_EVENT | FMU_CONT | FMU_TERMINATED) || n != n_expected) return -1;
    refresh(in, evaluate_in);
    for (k = 0; k < n; k++) out[k] = in->core.r[from[k]];
    return 0;
}

int fmu_get_continuous_states(FmuInstance *in, const char *function, double x[], size_t nx) {
    return get_vector(in, function, PAM_STATE_R, x, nx, PAM_NX, in ? in->flavour->states_evaluate_in : 0);
}

int fmu_get_derivatives(FmuInstance *in, const char *function, double dx[], size_t nx) {
    return get_vector(in, function, PAM_DERIV_R, dx, nx, PAM_NX, in ? in->flavour->derivatives_evaluate_in : 0);
}

int fmu_get_event_indicators(FmuInstance *in, const char *function, double z[], size_t nz) {
    return get_vector(in, function, PAM_INDICATOR_R, z, nz, PAM_NZ, in ? in->flavour->derivatives_evaluate_in : 0);
}

int fmu_get_nominals(FmuInstance *in, const char *function, double nominals[], size_t nx) {
    size_t k;
    if (!fmu_allowed(in, function, FMU_ANY) || nx != PAM_NX) return -1;
    for (k = 0; k < nx; k++) nominals[k] = PAM_NOMINAL[k];
    return 0;
}

/* ------------------------------------------------------------ Co-Simulation */

int fmu_do_step(FmuInstance *in, const char *function, double current_time, double step_size) {
    if (!fmu_allowed(in, function, FMU_STEP) || !in->is_cs) return FMU_STEP_REFUSED;
    if (!(step_size >= 0.0) || !isfinite(step_size)) {
        pam_logf(&in->core, PAM_LOG_ERROR, "%s: step size %g: must be a finite number >= 0", function, step_size);
        return FMU_STEP_REJECTED;
    }
    /* The importer's time may differ from the FMU's by rounding (t + h computed on either side),
     * not by more. */
    if (!(fabs(current_time - in->core.time_s) <= 1e-12 * fmax(1.0, fabs(in->core.time_s)))) {
        pam_logf(&in->core, PAM_LOG_ERROR, "%s: currentCommunicationPoint = %.16g s is not the FMU's time %.16g s",
                 function, current_time, in->core.time_s);
        return FMU_STEP_REJECTED;
    }
    in->core.time_s = current_time;
    if (pam_do_step(&in->core, current_time + step_size)) {
        in->state = FMU_ERROR;
        return FMU_STEP_FAILED;
    }
    return 0;
}
