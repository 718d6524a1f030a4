/* FMI 3.0 Model Exchange and Co-Simulation interface over pam_core. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "pam_core.h"

/* FMI 3.0 state machine (spec sec. 3.2, 4.2) */
enum {
    S_INSTANTIATED = 1 << 0,
    S_INIT = 1 << 1,
    S_EVENT = 1 << 2,
    S_CONT = 1 << 3,
    S_STEP = 1 << 4,
    S_TERMINATED = 1 << 5,
    S_ERROR = 1 << 6,
    S_CONFIG = 1 << 7
};
#define S_ANY (S_INSTANTIATED | S_INIT | S_EVENT | S_CONT | S_STEP | S_TERMINATED | S_ERROR | S_CONFIG)
#define S_RUNNING (S_INIT | S_EVENT | S_CONT | S_STEP | S_TERMINATED | S_ERROR)
#define VR_TIME 0u

typedef struct {
    PamCore core;
    int state;
    int is_cs;
    int logging_on;
    char *name;
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback logger;
} Instance;

static const char *level_category[] = {"logStatusOK", "logStatusWarning", "logStatusError"};

static void log_message(void *env, int level, const char *message) {
    Instance *in = (Instance *)env;
    fmi3Status status = level == PAM_LOG_ERROR ? fmi3Error : level == PAM_LOG_WARNING ? fmi3Warning : fmi3OK;
    if (in->logger && (in->logging_on || level != PAM_LOG_INFO))
        in->logger(in->env, status, level_category[level], message);
}

static int allowed(Instance *in, const char *function, int states) {
    if (!in) return 0;
    if (in->state & states) return 1;
    pam_logf(&in->core, PAM_LOG_ERROR, "%s: not allowed in the current state (FMI 3.0 state machine)", function);
    return 0;
}

const char *fmi3GetVersion(void) { return fmi3Version; }

static Instance *instantiate(fmi3String name, fmi3String token, fmi3Boolean loggingOn, fmi3InstanceEnvironment env,
                             fmi3LogMessageCallback logger, int is_cs) {
    Instance *in;
    if (!name || !*name) name = "pamsim_muscle";
    if (!token || strcmp(token, PAM_TOKEN) != 0) {
        if (logger) logger(env, fmi3Error, "logStatusError", "instantiation token does not match this binary");
        return NULL;
    }
    in = (Instance *)calloc(1, sizeof *in);
    if (!in) return NULL;
    in->name = (char *)malloc(strlen(name) + 1);
    if (in->name) strcpy(in->name, name);
    in->env = env;
    in->logger = logger;
    in->is_cs = is_cs;
    in->logging_on = loggingOn;
    pam_reset(&in->core);
    in->core.log = log_message;
    in->core.log_env = in;
    in->state = S_INSTANTIATED;
    return in;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage) {
    (void)resourcePath;
    (void)visible;
    return instantiate(instanceName, instantiationToken, loggingOn, instanceEnvironment, logMessage, 0);
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)resourcePath;
    (void)visible;
    (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables;
    (void)nRequiredIntermediateVariables;
    (void)intermediateUpdate;
    if (eventModeUsed) {
        if (logMessage) logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                                   "co-simulation event mode is not supported (the model has no clocks)");
        return NULL;
    }
    return instantiate(instanceName, instantiationToken, loggingOn, instanceEnvironment, logMessage, 1);
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instanceName;
    (void)instantiationToken;
    (void)resourcePath;
    (void)visible;
    (void)loggingOn;
    (void)clockUpdate;
    (void)lockPreemption;
    (void)unlockPreemption;
    if (logMessage) logMessage(instanceEnvironment, fmi3Error, "logStatusError", "scheduled execution is not supported");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance) {
    Instance *in = (Instance *)instance;
    if (!in) return;
    free(in->name);
    free(in);
}

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
    Instance *in = (Instance *)instance;
    (void)nCategories;
    (void)categories;
    if (!allowed(in, "fmi3SetDebugLogging", S_ANY)) return fmi3Error;
    in->logging_on = loggingOn;
    return fmi3OK;
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    Instance *in = (Instance *)instance;
    (void)stopTimeDefined;
    (void)stopTime;
    if (!allowed(in, "fmi3EnterInitializationMode", S_INSTANTIATED)) return fmi3Error;
    in->core.time_s = startTime;
    /* The importer's tolerance tightens the co-simulation integrator, never loosens the default. */
    if (toleranceDefined && tolerance > 0.0 && tolerance < in->core.r[R_cs_relative_tolerance])
        in->core.r[R_cs_relative_tolerance] = tolerance;
    in->state = S_INIT;
    return fmi3OK;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    Instance *in = (Instance *)instance;
    if (!allowed(in, "fmi3ExitInitializationMode", S_INIT)) return fmi3Error;
    if (pam_check_parameters(&in->core)) {
        in->state = S_ERROR;
        return fmi3Error;
    }
    pam_initialize(&in->core);
    in->state = in->is_cs ? S_STEP : S_EVENT;
    return fmi3OK;
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    Instance *in = (Instance *)instance;
    if (!allowed(in, "fmi3EnterEventMode", S_EVENT | S_CONT) || in->is_cs) return fmi3Error;
    in->state = S_EVENT;
    return fmi3OK;
}

fmi3Status fmi3Terminate(fmi3Instance instance) {
    Instance *in = (Instance *)instance;
    if (!allowed(in, "fmi3Terminate", S_EVENT | S_CONT | S_STEP)) return fmi3Error;
    in->state = S_TERMINATED;
    return fmi3OK;
}

fmi3Status fmi3Reset(fmi3Instance instance) {
    Instance *in = (Instance *)instance;
    if (!allowed(in, "fmi3Reset", S_ANY)) return fmi3Error;
    pam_reset(&in->core);
    in->state = S_INSTANTIATED;
    return fmi3OK;
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
    } else if (in->state & (S_EVENT | S_CONT)) pam_evaluate(&in->core);
}

static int check_vr(Instance *in, const char *function, fmi3ValueReference vr, char kind) {
    if (vr < 1 || vr > PAM_NVARS || PAM_VARS[vr - 1].kind != kind) {
        pam_logf(&in->core, PAM_LOG_ERROR, "%s: no %s variable with value reference %u", function,
                 kind == 'r' ? "Float64" : "Int32", vr);
        return 0;
    }
    return 1;
}

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 values[],
                          size_t nValues) {
    Instance *in = (Instance *)instance;
    size_t k;
    if (!allowed(in, "fmi3GetFloat64", S_RUNNING)) return fmi3Error;
    if (nValues != nvr) return fmi3Error;
    refresh(in);
    for (k = 0; k < nvr; k++) {
        if (vr[k] == VR_TIME) {
            values[k] = in->core.time_s;
            continue;
        }
        if (!check_vr(in, "fmi3GetFloat64", vr[k], 'r')) return fmi3Error;
        values[k] = in->core.r[PAM_VARS[vr[k] - 1].index];
    }
    return fmi3OK;
}

fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Int32 values[],
                        size_t nValues) {
    Instance *in = (Instance *)instance;
    size_t k;
    if (!allowed(in, "fmi3GetInt32", S_RUNNING)) return fmi3Error;
    if (nValues != nvr) return fmi3Error;
    refresh(in);
    for (k = 0; k < nvr; k++) {
        if (!check_vr(in, "fmi3GetInt32", vr[k], 'i')) return fmi3Error;
        values[k] = in->core.i[PAM_VARS[vr[k] - 1].index];
    }
    return fmi3OK;
}

/* Parameters before the end of initialisation, inputs at any time before termination. */
static int settable(Instance *in, const char *function, fmi3ValueReference vr) {
    PamCausality cz = PAM_VARS[vr - 1].causality;
    if (cz == PAM_INPUT && (in->state & (S_INSTANTIATED | S_INIT | S_EVENT | S_CONT | S_STEP))) return 1;
    if (cz == PAM_PARAMETER && (in->state & (S_INSTANTIATED | S_INIT))) return 1;
    pam_logf(&in->core, PAM_LOG_ERROR, "%s: %s cannot be set %s", function, PAM_VARS[vr - 1].name,
             cz == PAM_PARAMETER ? "after initialization (fixed parameter)" : "(not a parameter or input)");
    return 0;
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3Float64 values[],
                          size_t nValues) {
    Instance *in = (Instance *)instance;
    size_t k;
    if (!allowed(in, "fmi3SetFloat64", S_INSTANTIATED | S_INIT | S_EVENT | S_CONT | S_STEP)) return fmi3Error;
    if (nValues != nvr) return fmi3Error;
    for (k = 0; k < nvr; k++) {
        double *dst;
        if (!check_vr(in, "fmi3SetFloat64", vr[k], 'r') || !settable(in, "fmi3SetFloat64", vr[k])) return fmi3Error;
        if (pam_check_value(&in->core, vr[k], values[k])) return fmi3Error;
        dst = &in->core.r[PAM_VARS[vr[k] - 1].index];
        if (*dst != values[k]) in->core.inputs_changed = 1;
        *dst = values[k];
    }
    return fmi3OK;
}

fmi3Status fmi3SetInt32(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3Int32 values[],
                        size_t nValues) {
    Instance *in = (Instance *)instance;
    size_t k;
    if (!allowed(in, "fmi3SetInt32", S_INSTANTIATED | S_INIT)) return fmi3Error;
    if (nValues != nvr) return fmi3Error;
    for (k = 0; k < nvr; k++) {
        if (!check_vr(in, "fmi3SetInt32", vr[k], 'i') || !settable(in, "fmi3SetInt32", vr[k])) return fmi3Error;
        in->core.i[PAM_VARS[vr[k] - 1].index] = values[k];
    }
    return fmi3OK;
}

/* The model has no variables of the other types: any non-empty access is an error. */
#define NO_SUCH_TYPE(NAME, CTYPE, CONST)                                                                            \
    fmi3Status NAME(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, CONST CTYPE values[],        \
                    size_t nValues) {                                                                             \
        Instance *in = (Instance *)instance;                                                                      \
        (void)vr;                                                                                                 \
        (void)values;                                                                                             \
        (void)nValues;                                                                                            \
        if (!allowed(in, #NAME, S_ANY)) return fmi3Error;                                                         \
        if (nvr == 0) return fmi3OK;                                                                              \
        pam_logf(&in->core, PAM_LOG_ERROR, "%s: the model has no variables of this type", #NAME);                 \
        return fmi3Error;                                                                                         \
    }
NO_SUCH_TYPE(fmi3GetFloat32, fmi3Float32, )
NO_SUCH_TYPE(fmi3GetInt8, fmi3Int8, )
NO_SUCH_TYPE(fmi3GetUInt8, fmi3UInt8, )
NO_SUCH_TYPE(fmi3GetInt16, fmi3Int16, )
NO_SUCH_TYPE(fmi3GetUInt16, fmi3UInt16, )
NO_SUCH_TYPE(fmi3GetUInt32, fmi3UInt32, )
NO_SUCH_TYPE(fmi3GetInt64, fmi3Int64, )
NO_SUCH_TYPE(fmi3GetUInt64, fmi3UInt64, )
NO_SUCH_TYPE(fmi3GetBoolean, fmi3Boolean, )
NO_SUCH_TYPE(fmi3GetString, fmi3String, )
NO_SUCH_TYPE(fmi3SetFloat32, fmi3Float32, const)
NO_SUCH_TYPE(fmi3SetInt8, fmi3Int8, const)
NO_SUCH_TYPE(fmi3SetUInt8, fmi3UInt8, const)
NO_SUCH_TYPE(fmi3SetInt16, fmi3Int16, const)
NO_SUCH_TYPE(fmi3SetUInt16, fmi3UInt16, const)
NO_SUCH_TYPE(fmi3SetUInt32, fmi3UInt32, const)
NO_SUCH_TYPE(fmi3SetInt64, fmi3Int64, const)
NO_SUCH_TYPE(fmi3SetUInt64, fmi3UInt64, const)
NO_SUCH_TYPE(fmi3SetBoolean, fmi3Boolean, const)
NO_SUCH_TYPE(fmi3SetString, fmi3String, const)

static fmi3Status unsupported(fmi3Instance instance, const char *function) {
    Instance *in = (Instance *)instance;
    if (in) pam_logf(&in->core, PAM_LOG_ERROR, "%s: not supported by this FMU", function);
    return fmi3Error;
}

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, size_t valueSizes[],
                         fmi3Binary values[], size_t nValues) {
    (void)vr;
    (void)valueSizes;
    (void)values;
    (void)nValues;
    return nvr == 0 ? fmi3OK : unsupported(instance, "fmi3GetBinary");
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const size_t valueSizes[],
                         const fmi3Binary values[], size_t nValues) {
    (void)vr;
    (void)valueSizes;
    (void)values;
    (void)nValues;
    return nvr == 0 ? fmi3OK : unsupported(instance, "fmi3SetBinary");
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Clock values[]) {
    (void)vr;
    (void)values;
    return nvr == 0 ? fmi3OK : unsupported(instance, "fmi3GetClock");
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3Clock values[]) {
    (void)vr;
    (void)values;
    return nvr == 0 ? fmi3OK : unsupported(instance, "fmi3SetClock");
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference,
                                               size_t *nDependencies) {
    (void)valueReference;
    (void)nDependencies;
    return unsupported(instance, "fmi3GetNumberOfVariableDependencies");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies) {
    (void)dependent;
    (void)elementIndicesOfDependent;
    (void)independents;
    (void)elementIndicesOfIndependents;
    (void)dependencyKinds;
    (void)nDependencies;
    return unsupported(instance, "fmi3GetVariableDependencies");
}

/* ------------------------------------------------------------ FMU state */

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *s) {
    Instance *in = (Instance *)instance;
    Instance *copy;
    if (!allowed(in, "fmi3GetFMUState", S_ANY)) return fmi3Error;
    copy = *s ? (Instance *)*s : (Instance *)malloc(sizeof *copy);
    if (!copy) return fmi3Error;
    *copy = *in;
    copy->name = NULL;
    *s = copy;
    return fmi3OK;
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState s) {
    Instance *in = (Instance *)instance;
    char *name;
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback logger;
    int logging_on, is_cs;
    if (!allowed(in, "fmi3SetFMUState", S_ANY) || !s) return fmi3Error;
    name = in->name;
    env = in->env;
    logger = in->logger;
    logging_on = in->logging_on;
    is_cs = in->is_cs;
    *in = *(const Instance *)s;
    in->name = name;
    in->env = env;
    in->logger = logger;
    in->logging_on = logging_on;
    in->is_cs = is_cs;
    in->core.log = log_message;
    in->core.log_env = in;
    return fmi3OK;
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *s) {
    Instance *in = (Instance *)instance;
    if (!allowed(in, "fmi3FreeFMUState", S_ANY)) return fmi3Error;
    if (s && *s) {
        free(*s);
        *s = NULL;
    }
    return fmi3OK;
}

/* The serialized form is the state struct behind the token of this build. */
#define SERIAL_SIZE (sizeof(PAM_TOKEN) + sizeof(Instance))

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState s, size_t *size) {
    Instance *in = (Instance *)instance;
    (void)s;
    if (!allowed(in, "fmi3SerializedFMUStateSize", S_ANY)) return fmi3Error;
    *size = SERIAL_SIZE;
    return fmi3OK;
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState s, fmi3Byte bytes[], size_t size) {
    Instance *in = (Instance *)instance;
    if (!allowed(in, "fmi3SerializeFMUState", S_ANY) || !s || size < SERIAL_SIZE) return fmi3Error;
    memcpy(bytes, PAM_TOKEN, sizeof(PAM_TOKEN));
    memcpy(bytes + sizeof(PAM_TOKEN), s, sizeof(Instance));
    return fmi3OK;
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte bytes[], size_t size, fmi3FMUState *s) {
    Instance *in = (Instance *)instance;
    Instance *copy;
    if (!allowed(in, "fmi3DeserializeFMUState", S_ANY)) return fmi3Error;
    if (size != SERIAL_SIZE || memcmp(bytes, PAM_TOKEN, sizeof(PAM_TOKEN)) != 0) {
        pam_logf(&in->core, PAM_LOG_ERROR, "fmi3DeserializeFMUState: the bytes are not a state of this FMU build");
        return fmi3Error;
    }
    copy = *s ? (Instance *)*s : (Instance *)malloc(sizeof *copy);
    if (!copy) return fmi3Error;
    memcpy(copy, bytes + sizeof(PAM_TOKEN), sizeof(Instance));
    copy->name = NULL;
    *s = copy;
    return fmi3OK;
}

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    Instance *in = (Instance *)instance;
    if (!allowed(in, "fmi3GetDirectionalDerivative", S_INIT | S_EVENT | S_CONT | S_STEP | S_TERMINATED))
        return fmi3Error;
    if (nSeed != nKnowns || nSensitivity != nUnknowns
        || pam_directional_derivative(&in->core, unknowns, (int)nUnknowns, knowns, (int)nKnowns, seed, sensitivity)) {
        pam_logf(&in->core, PAM_LOG_ERROR, "fmi3GetDirectionalDerivative: only Float64 scalars can be differentiated");
        return fmi3Error;
    }
    return fmi3OK;
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)unknowns;
    (void)nUnknowns;
    (void)knowns;
    (void)nKnowns;
    (void)seed;
    (void)nSeed;
    (void)sensitivity;
    (void)nSensitivity;
    return unsupported(instance, "fmi3GetAdjointDerivative");
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) { return unsupported(instance, "fmi3EnterConfigurationMode"); }
fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) { return unsupported(instance, "fmi3ExitConfigurationMode"); }

fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                                  fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[]) {
    (void)vr;
    (void)nvr;
    (void)intervals;
    (void)qualifiers;
    return unsupported(instance, "fmi3GetIntervalDecimal");
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                                   fmi3UInt64 counters[], fmi3UInt64 resolutions[], fmi3IntervalQualifier qualifiers[]) {
    (void)vr;
    (void)nvr;
    (void)counters;
    (void)resolutions;
    (void)qualifiers;
    return unsupported(instance, "fmi3GetIntervalFraction");
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 shifts[]) {
    (void)vr;
    (void)nvr;
    (void)shifts;
    return unsupported(instance, "fmi3GetShiftDecimal");
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3UInt64 counters[],
                                fmi3UInt64 resolutions[]) {
    (void)vr;
    (void)nvr;
    (void)counters;
    (void)resolutions;
    return unsupported(instance, "fmi3GetShiftFraction");
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                                  const fmi3Float64 intervals[]) {
    (void)vr;
    (void)nvr;
    (void)intervals;
    return unsupported(instance, "fmi3SetIntervalDecimal");
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                                   const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]) {
    (void)vr;
    (void)nvr;
    (void)counters;
    (void)resolutions;
    return unsupported(instance, "fmi3SetIntervalFraction");
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                               const fmi3Float64 shifts[]) {
    (void)vr;
    (void)nvr;
    (void)shifts;
    return unsupported(instance, "fmi3SetShiftDecimal");
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                                const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]) {
    (void)vr;
    (void)nvr;
    (void)counters;
    (void)resolutions;
    return unsupported(instance, "fmi3SetShiftFraction");
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) {
    return unsupported(instance, "fmi3EvaluateDiscreteStates");
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime) {
    Instance *in = (Instance *)instance;
    if (!allowed(in, "fmi3UpdateDiscreteStates", S_EVENT)) return fmi3Error;
    *valuesOfContinuousStatesChanged = pam_event_update(&in->core) ? fmi3True : fmi3False;
    *discreteStatesNeedUpdate = fmi3False;
    *terminateSimulation = fmi3False;
    *nominalsOfContinuousStatesChanged = fmi3False;
    *nextEventTimeDefined = fmi3False;
    *nextEventTime = 0.0;
    return fmi3OK;
}

/* ------------------------------------------------------------ Model Exchange */

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    Instance *in = (Instance *)instance;
    if (!allowed(in, "fmi3EnterContinuousTimeMode", S_EVENT)) return fmi3Error;
    in->state = S_CONT;
    return fmi3OK;
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation) {
    Instance *in = (Instance *)instance;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (!allowed(in, "fmi3CompletedIntegratorStep", S_CONT)) return fmi3Error;
    *enterEventMode = fmi3False;
    *terminateSimulation = fmi3False;
    return fmi3OK;
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    Instance *in = (Instance *)instance;
    if (!allowed(in, "fmi3SetTime", S_EVENT | S_CONT)) return fmi3Error;
    in->core.time_s = time;
    return fmi3OK;
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 x[], size_t nx) {
    Instance *in = (Instance *)instance;
    size_t k;
    if (!allowed(in, "fmi3SetContinuousStates", S_CONT) || nx != PAM_NX) return fmi3Error;
    for (k = 0; k < nx; k++) {
        if (!isfinite(x[k])) {
            pam_logf(&in->core, PAM_LOG_ERROR, "fmi3SetContinuousStates: state %u is not finite", (unsigned)k);
            return fmi3Error;
        }
        in->core.r[PAM_STATE_R[k]] = x[k];
    }
    return fmi3OK;
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 dx[], size_t nx) {
    Instance *in = (Instance *)instance;
    size_t k;
    if (!allowed(in, "fmi3GetContinuousStateDerivatives", S_INIT | S_EVENT | S_CONT | S_TERMINATED) || nx != PAM_NX)
        return fmi3Error;
    refresh(in);
    for (k = 0; k < nx; k++) dx[k] = in->core.r[PAM_DERIV_R[k]];
    return fmi3OK;
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 z[], size_t nz) {
    Instance *in = (Instance *)instance;
    if (!allowed(in, "fmi3GetEventIndicators", S_INIT | S_EVENT | S_CONT | S_TERMINATED) || nz != PAM_NZ)
        return fmi3Error;
    refresh(in);
    z[0] = in->core.r[R_event_indicator_1];
    z[1] = in->core.r[R_event_indicator_2];
    return fmi3OK;
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 x[], size_t nx) {
    Instance *in = (Instance *)instance;
    size_t k;
    if (!allowed(in, "fmi3GetContinuousStates", S_INIT | S_EVENT | S_CONT | S_TERMINATED) || nx != PAM_NX)
        return fmi3Error;
    refresh(in);
    for (k = 0; k < nx; k++) x[k] = in->core.r[PAM_STATE_R[k]];
    return fmi3OK;
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t nx) {
    Instance *in = (Instance *)instance;
    size_t k;
    if (!allowed(in, "fmi3GetNominalsOfContinuousStates", S_ANY) || nx != PAM_NX) return fmi3Error;
    for (k = 0; k < nx; k++) nominals[k] = PAM_NOMINAL[k];
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *n) {
    Instance *in = (Instance *)instance;
    if (!allowed(in, "fmi3GetNumberOfEventIndicators", S_ANY)) return fmi3Error;
    *n = PAM_NZ;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *n) {
    Instance *in = (Instance *)instance;
    if (!allowed(in, "fmi3GetNumberOfContinuousStates", S_ANY)) return fmi3Error;
    *n = PAM_NX;
    return fmi3OK;
}

/* ------------------------------------------------------------ Co-Simulation */

fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    Instance *in = (Instance *)instance;
    if (!allowed(in, "fmi3EnterStepMode", S_STEP) || !in->is_cs) return fmi3Error;
    return fmi3OK;
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                                    const fmi3Int32 orders[], fmi3Float64 values[], size_t nValues) {
    (void)vr;
    (void)nvr;
    (void)orders;
    (void)values;
    (void)nValues;
    return unsupported(instance, "fmi3GetOutputDerivatives");
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    Instance *in = (Instance *)instance;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (!allowed(in, "fmi3DoStep", S_STEP) || !in->is_cs) return fmi3Error;
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = fmi3False;
    if (!(communicationStepSize >= 0.0) || !isfinite(currentCommunicationPoint)) {
        pam_logf(&in->core, PAM_LOG_ERROR, "fmi3DoStep: invalid step size %g", communicationStepSize);
        return fmi3Error;
    }
    in->core.time_s = currentCommunicationPoint;
    if (pam_do_step(&in->core, currentCommunicationPoint + communicationStepSize)) {
        in->state = S_ERROR;
        *lastSuccessfulTime = in->core.time_s;
        return fmi3Error;
    }
    *lastSuccessfulTime = in->core.time_s;
    return fmi3OK;
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime) {
    (void)clockReference;
    (void)activationTime;
    return unsupported(instance, "fmi3ActivateModelPartition");
}
