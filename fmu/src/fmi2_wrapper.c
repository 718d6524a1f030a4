/* FMI 2.0 Model Exchange and Co-Simulation interface over pam_core. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "pam_core.h"

/* FMI 2.0 state machine (spec sec. 3.2.3 and 4.2.4) */
enum {
    S_INSTANTIATED = 1 << 0,
    S_INIT = 1 << 1,
    S_EVENT = 1 << 2,
    S_CONT = 1 << 3,
    S_STEP = 1 << 4,
    S_TERMINATED = 1 << 5,
    S_ERROR = 1 << 6
};
#define S_ANY (S_INSTANTIATED | S_INIT | S_EVENT | S_CONT | S_STEP | S_TERMINATED | S_ERROR)
#define S_RUNNING (S_INIT | S_EVENT | S_CONT | S_STEP | S_TERMINATED | S_ERROR)

typedef struct {
    PamCore core;
    int state;
    int is_cs;
    int logging_on;
    char *name;
    fmi2CallbackFunctions cb;
} Instance;

static const char *level_category[] = {"logStatusOK", "logStatusWarning", "logStatusError"};

static void log_message(void *env, int level, const char *message) {
    Instance *in = (Instance *)env;
    fmi2Status status = level == PAM_LOG_ERROR ? fmi2Error : level == PAM_LOG_WARNING ? fmi2Warning : fmi2OK;
    if (in->cb.logger && (in->logging_on || level != PAM_LOG_INFO))
        in->cb.logger(in->cb.componentEnvironment, in->name, status, level_category[level], "%s", message);
}

static int allowed(Instance *in, const char *function, int states) {
    if (!in) return 0;
    if (in->state & states) return 1;
    pam_logf(&in->core, PAM_LOG_ERROR, "%s: not allowed in the current state (FMI 2.0 state machine)", function);
    return 0;
}

static char *copy_string(const char *s) {
    char *d = (char *)malloc(strlen(s) + 1);
    if (d) strcpy(d, s);
    return d;
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    Instance *in;
    (void)fmuResourceLocation;
    (void)visible;
    if (!functions || !functions->logger) return NULL;
    if (!instanceName || !*instanceName) instanceName = "pamsim_muscle";
    if (!fmuGUID || strcmp(fmuGUID, PAM_TOKEN) != 0) {
        functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError",
                          "GUID %s does not match this binary's %s", fmuGUID ? fmuGUID : "(null)", PAM_TOKEN);
        return NULL;
    }
    in = (Instance *)calloc(1, sizeof *in);
    if (!in) return NULL;
    in->name = copy_string(instanceName);
    in->cb = *functions;
    in->is_cs = fmuType == fmi2CoSimulation;
    in->logging_on = loggingOn;
    pam_reset(&in->core);
    in->core.log = log_message;
    in->core.log_env = in;
    in->state = S_INSTANTIATED;
    return in;
}

void fmi2FreeInstance(fmi2Component c) {
    Instance *in = (Instance *)c;
    if (!in) return;
    free(in->name);
    free(in);
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t n, const fmi2String cats[]) {
    Instance *in = (Instance *)c;
    (void)n;
    (void)cats;
    if (!allowed(in, "fmi2SetDebugLogging", S_ANY)) return fmi2Error;
    in->logging_on = loggingOn;
    return fmi2OK;
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    Instance *in = (Instance *)c;
    (void)stopTimeDefined;
    (void)stopTime;
    if (!allowed(in, "fmi2SetupExperiment", S_INSTANTIATED)) return fmi2Error;
    in->core.time_s = startTime;
    /* The importer's tolerance tightens the co-simulation integrator, never loosens the default. */
    if (toleranceDefined && tolerance > 0.0 && tolerance < in->core.r[R_cs_relative_tolerance])
        in->core.r[R_cs_relative_tolerance] = tolerance;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    Instance *in = (Instance *)c;
    if (!allowed(in, "fmi2EnterInitializationMode", S_INSTANTIATED)) return fmi2Error;
    in->state = S_INIT;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Instance *in = (Instance *)c;
    if (!allowed(in, "fmi2ExitInitializationMode", S_INIT)) return fmi2Error;
    if (pam_check_parameters(&in->core)) {
        in->state = S_ERROR;
        return fmi2Error;
    }
    pam_initialize(&in->core);
    in->state = in->is_cs ? S_STEP : S_EVENT;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c) {
    Instance *in = (Instance *)c;
    if (!allowed(in, "fmi2Terminate", S_EVENT | S_CONT | S_STEP)) return fmi2Error;
    in->state = S_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) {
    Instance *in = (Instance *)c;
    if (!allowed(in, "fmi2Reset", S_ANY)) return fmi2Error;
    pam_reset(&in->core);
    in->state = S_INSTANTIATED;
    return fmi2OK;
}

/* Outputs of the initialization mode follow the parameters set so far; invalid ones are
 * reported once, by ExitInitializationMode, not at every read. */
static void refresh(Instance *in) {
    PamLogFn log = in->core.log;
    int valid;
    if (in->state == S_INIT) {
        in->core.log = 0;
        valid = pam_check_parameters(&in->core) == 0;
        in->core.log = log;
        if (valid) pam_initialize(&in->core);
    }
}

static int check_vr(Instance *in, const char *function, fmi2ValueReference vr, char kind) {
    if (vr < 1 || vr > PAM_NVARS || PAM_VARS[vr - 1].kind != kind) {
        pam_logf(&in->core, PAM_LOG_ERROR, "%s: no %s variable with value reference %u", function,
                 kind == 'r' ? "Real" : "Integer", vr);
        return 0;
    }
    return 1;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    Instance *in = (Instance *)c;
    size_t k;
    if (!allowed(in, "fmi2GetReal", S_RUNNING)) return fmi2Error;
    refresh(in);
    if (in->state & (S_EVENT | S_CONT)) pam_evaluate(&in->core);
    for (k = 0; k < nvr; k++) {
        if (!check_vr(in, "fmi2GetReal", vr[k], 'r')) return fmi2Error;
        value[k] = in->core.r[PAM_VARS[vr[k] - 1].index];
    }
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
    Instance *in = (Instance *)c;
    size_t k;
    if (!allowed(in, "fmi2GetInteger", S_RUNNING)) return fmi2Error;
    refresh(in);
    if (in->state & (S_EVENT | S_CONT)) pam_evaluate(&in->core);
    for (k = 0; k < nvr; k++) {
        if (!check_vr(in, "fmi2GetInteger", vr[k], 'i')) return fmi2Error;
        value[k] = in->core.i[PAM_VARS[vr[k] - 1].index];
    }
    return fmi2OK;
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
    Instance *in = (Instance *)c;
    (void)vr;
    (void)value;
    if (!allowed(in, "fmi2GetBoolean", S_RUNNING)) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    pam_logf(&in->core, PAM_LOG_ERROR, "fmi2GetBoolean: the model has no Boolean variables");
    return fmi2Error;
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
    Instance *in = (Instance *)c;
    (void)vr;
    (void)value;
    if (!allowed(in, "fmi2GetString", S_RUNNING)) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    pam_logf(&in->core, PAM_LOG_ERROR, "fmi2GetString: the model has no String variables");
    return fmi2Error;
}

/* Parameters before the end of initialisation, inputs at any time before termination. */
static int settable(Instance *in, const char *function, fmi2ValueReference vr) {
    PamCausality cz = PAM_VARS[vr - 1].causality;
    if (cz == PAM_INPUT && (in->state & (S_INSTANTIATED | S_INIT | S_EVENT | S_CONT | S_STEP))) return 1;
    if (cz == PAM_PARAMETER && (in->state & (S_INSTANTIATED | S_INIT))) return 1;
    pam_logf(&in->core, PAM_LOG_ERROR, "%s: %s cannot be set %s", function, PAM_VARS[vr - 1].name,
             cz == PAM_PARAMETER ? "after initialization (fixed parameter)" : "(not a parameter or input)");
    return 0;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    Instance *in = (Instance *)c;
    size_t k;
    if (!allowed(in, "fmi2SetReal", S_INSTANTIATED | S_INIT | S_EVENT | S_CONT | S_STEP)) return fmi2Error;
    for (k = 0; k < nvr; k++) {
        double *dst;
        if (!check_vr(in, "fmi2SetReal", vr[k], 'r') || !settable(in, "fmi2SetReal", vr[k])) return fmi2Error;
        if (pam_check_value(&in->core, vr[k], value[k])) return fmi2Error;
        dst = &in->core.r[PAM_VARS[vr[k] - 1].index];
        if (*dst != value[k]) in->core.inputs_changed = 1;
        *dst = value[k];
    }
    return fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[]) {
    Instance *in = (Instance *)c;
    size_t k;
    if (!allowed(in, "fmi2SetInteger", S_INSTANTIATED | S_INIT)) return fmi2Error;
    for (k = 0; k < nvr; k++) {
        if (!check_vr(in, "fmi2SetInteger", vr[k], 'i') || !settable(in, "fmi2SetInteger", vr[k])) return fmi2Error;
        in->core.i[PAM_VARS[vr[k] - 1].index] = value[k];
    }
    return fmi2OK;
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[]) {
    Instance *in = (Instance *)c;
    (void)vr;
    (void)value;
    if (!allowed(in, "fmi2SetBoolean", S_ANY)) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    pam_logf(&in->core, PAM_LOG_ERROR, "fmi2SetBoolean: the model has no Boolean variables");
    return fmi2Error;
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
    Instance *in = (Instance *)c;
    (void)vr;
    (void)value;
    if (!allowed(in, "fmi2SetString", S_ANY)) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    pam_logf(&in->core, PAM_LOG_ERROR, "fmi2SetString: the model has no String variables");
    return fmi2Error;
}

/* ------------------------------------------------------------ FMU state */

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) {
    Instance *in = (Instance *)c;
    Instance *copy;
    if (!allowed(in, "fmi2GetFMUstate", S_ANY)) return fmi2Error;
    copy = *s ? (Instance *)*s : (Instance *)malloc(sizeof *copy);
    if (!copy) return fmi2Error;
    *copy = *in;
    copy->name = NULL;
    *s = copy;
    return fmi2OK;
}

static void restore(Instance *in, const Instance *saved) {
    char *name = in->name;
    fmi2CallbackFunctions cb = in->cb;
    int logging_on = in->logging_on, is_cs = in->is_cs;
    *in = *saved;
    in->name = name;
    in->cb = cb;
    in->logging_on = logging_on;
    in->is_cs = is_cs;
    in->core.log = log_message;
    in->core.log_env = in;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) {
    Instance *in = (Instance *)c;
    if (!allowed(in, "fmi2SetFMUstate", S_ANY)) return fmi2Error;
    if (!s) return fmi2Error;
    restore(in, (const Instance *)s);
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) {
    Instance *in = (Instance *)c;
    if (!allowed(in, "fmi2FreeFMUstate", S_ANY)) return fmi2Error;
    if (s && *s) {
        free(*s);
        *s = NULL;
    }
    return fmi2OK;
}

/* The serialized form is the state struct behind the token of this build. */
#define SERIAL_SIZE (sizeof(PAM_TOKEN) + sizeof(Instance))

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *size) {
    Instance *in = (Instance *)c;
    (void)s;
    if (!allowed(in, "fmi2SerializedFMUstateSize", S_ANY)) return fmi2Error;
    *size = SERIAL_SIZE;
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte bytes[], size_t size) {
    Instance *in = (Instance *)c;
    if (!allowed(in, "fmi2SerializeFMUstate", S_ANY)) return fmi2Error;
    if (!s || size < SERIAL_SIZE) return fmi2Error;
    memcpy(bytes, PAM_TOKEN, sizeof(PAM_TOKEN));
    memcpy(bytes + sizeof(PAM_TOKEN), s, sizeof(Instance));
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate *s) {
    Instance *in = (Instance *)c;
    Instance *copy;
    if (!allowed(in, "fmi2DeSerializeFMUstate", S_ANY)) return fmi2Error;
    if (size != SERIAL_SIZE || memcmp(bytes, PAM_TOKEN, sizeof(PAM_TOKEN)) != 0) {
        pam_logf(&in->core, PAM_LOG_ERROR, "fmi2DeSerializeFMUstate: the bytes are not a state of this FMU build");
        return fmi2Error;
    }
    copy = *s ? (Instance *)*s : (Instance *)malloc(sizeof *copy);
    if (!copy) return fmi2Error;
    memcpy(copy, bytes + sizeof(PAM_TOKEN), sizeof(Instance));
    copy->name = NULL;
    *s = copy;
    return fmi2OK;
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown, const fmi2Real dvKnown[],
                                        fmi2Real dvUnknown[]) {
    Instance *in = (Instance *)c;
    if (!allowed(in, "fmi2GetDirectionalDerivative", S_INIT | S_EVENT | S_CONT | S_STEP | S_TERMINATED))
        return fmi2Error;
    if (pam_directional_derivative(&in->core, vUnknown_ref, (int)nUnknown, vKnown_ref, (int)nKnown, dvKnown,
                                   dvUnknown)) {
        pam_logf(&in->core, PAM_LOG_ERROR, "fmi2GetDirectionalDerivative: only Real variables can be differentiated");
        return fmi2Error;
    }
    return fmi2OK;
}

/* ------------------------------------------------------------ Model Exchange */

fmi2Status fmi2EnterEventMode(fmi2Component c) {
    Instance *in = (Instance *)c;
    if (!allowed(in, "fmi2EnterEventMode", S_EVENT | S_CONT) || in->is_cs) return fmi2Error;
    in->state = S_EVENT;
    return fmi2OK;
}

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) {
    Instance *in = (Instance *)c;
    if (!allowed(in, "fmi2NewDiscreteStates", S_EVENT)) return fmi2Error;
    info->valuesOfContinuousStatesChanged = pam_event_update(&in->core) ? fmi2True : fmi2False;
    info->newDiscreteStatesNeeded = fmi2False;
    info->terminateSimulation = fmi2False;
    info->nominalsOfContinuousStatesChanged = fmi2False;
    info->nextEventTimeDefined = fmi2False;
    info->nextEventTime = 0.0;
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) {
    Instance *in = (Instance *)c;
    if (!allowed(in, "fmi2EnterContinuousTimeMode", S_EVENT)) return fmi2Error;
    in->state = S_CONT;
    return fmi2OK;
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation) {
    Instance *in = (Instance *)c;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (!allowed(in, "fmi2CompletedIntegratorStep", S_CONT)) return fmi2Error;
    *enterEventMode = fmi2False;
    *terminateSimulation = fmi2False;
    return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
    Instance *in = (Instance *)c;
    if (!allowed(in, "fmi2SetTime", S_EVENT | S_CONT)) return fmi2Error;
    in->core.time_s = time;
    return fmi2OK;
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
    Instance *in = (Instance *)c;
    size_t k;
    if (!allowed(in, "fmi2SetContinuousStates", S_CONT)) return fmi2Error;
    if (nx != PAM_NX) return fmi2Error;
    for (k = 0; k < nx; k++) {
        if (!isfinite(x[k])) {
            pam_logf(&in->core, PAM_LOG_ERROR, "fmi2SetContinuousStates: state %u is not finite", (unsigned)k);
            return fmi2Error;
        }
        in->core.r[PAM_STATE_R[k]] = x[k];
    }
    return fmi2OK;
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real dx[], size_t nx) {
    Instance *in = (Instance *)c;
    size_t k;
    if (!allowed(in, "fmi2GetDerivatives", S_INIT | S_EVENT | S_CONT | S_TERMINATED) || nx != PAM_NX)
        return fmi2Error;
    refresh(in);
    pam_evaluate(&in->core);
    for (k = 0; k < nx; k++) dx[k] = in->core.r[PAM_DERIV_R[k]];
    return fmi2OK;
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real z[], size_t nz) {
    Instance *in = (Instance *)c;
    if (!allowed(in, "fmi2GetEventIndicators", S_INIT | S_EVENT | S_CONT | S_TERMINATED) || nz != PAM_NZ)
        return fmi2Error;
    refresh(in);
    pam_evaluate(&in->core);
    z[0] = in->core.r[R_event_indicator_1];
    z[1] = in->core.r[R_event_indicator_2];
    return fmi2OK;
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
    Instance *in = (Instance *)c;
    size_t k;
    if (!allowed(in, "fmi2GetContinuousStates", S_INIT | S_EVENT | S_CONT | S_TERMINATED) || nx != PAM_NX)
        return fmi2Error;
    refresh(in);
    for (k = 0; k < nx; k++) x[k] = in->core.r[PAM_STATE_R[k]];
    return fmi2OK;
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[], size_t nx) {
    Instance *in = (Instance *)c;
    size_t k;
    if (!allowed(in, "fmi2GetNominalsOfContinuousStates", S_ANY) || nx != PAM_NX) return fmi2Error;
    for (k = 0; k < nx; k++) x_nominal[k] = PAM_NOMINAL[k];
    return fmi2OK;
}

/* ------------------------------------------------------------ Co-Simulation */

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    Instance *in = (Instance *)c;
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    if (in) pam_logf(&in->core, PAM_LOG_ERROR, "fmi2SetRealInputDerivatives: not supported (inputs are held over a step)");
    return fmi2Error;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    Instance *in = (Instance *)c;
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    if (in) pam_logf(&in->core, PAM_LOG_ERROR, "fmi2GetRealOutputDerivatives: not supported");
    return fmi2Error;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentCommunicationPoint) {
    Instance *in = (Instance *)c;
    (void)noSetFMUStatePriorToCurrentCommunicationPoint;
    if (!allowed(in, "fmi2DoStep", S_STEP) || !in->is_cs) return fmi2Error;
    if (!(communicationStepSize >= 0.0) || !isfinite(currentCommunicationPoint)) {
        pam_logf(&in->core, PAM_LOG_ERROR, "fmi2DoStep: invalid step size %g", communicationStepSize);
        return fmi2Error;
    }
    in->core.time_s = currentCommunicationPoint;
    if (pam_do_step(&in->core, currentCommunicationPoint + communicationStepSize)) {
        in->state = S_ERROR;
        return fmi2Error;
    }
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    Instance *in = (Instance *)c;
    if (in) pam_logf(&in->core, PAM_LOG_ERROR, "fmi2CancelStep: steps are synchronous and cannot be cancelled");
    return fmi2Error;
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)c;
    (void)s;
    (void)value;
    return fmi2Discard;
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    Instance *in = (Instance *)c;
    if (!in) return fmi2Error;
    if (s == fmi2LastSuccessfulTime) {
        *value = in->core.time_s;
        return fmi2OK;
    }
    return fmi2Discard;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)c;
    (void)s;
    (void)value;
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    (void)c;
    (void)s;
    (void)value;
    return fmi2Discard;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)c;
    (void)s;
    (void)value;
    return fmi2Discard;
}
