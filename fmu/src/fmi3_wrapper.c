/* FMI 3.0 Model Exchange and Co-Simulation interface: translates the calls to fmi_shell. */
#include <string.h>

#include "fmi3Functions.h"
#include "fmi_shell.h"

typedef struct {
    FmuInstance fmu; /* first, so that an instance is an FmuInstance */
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback logger;
} Instance;

static const FmuFlavour FMI3 = {.standard = "FMI 3.0",
                                .real_type = "Float64",
                                .integer_type = "Int32",
                                .differentiable = "Float64 scalars",
                                .time_is_vr0 = 1,
                                .enums_are_int64 = 1,
                                .states_evaluate_in = FMU_EVENT | FMU_CONT,
                                /* As FMI 2: a read after Terminate or during initialization sees the current values. */
                                .derivatives_evaluate_in = FMU_INIT | FMU_EVENT | FMU_CONT | FMU_TERMINATED};

#define FMU(instance) ((FmuInstance *)(instance))
#define STATUS(rc) ((rc) ? fmi3Error : fmi3OK)

static void log_message(void *env, int level, const char *message) {
    static const fmi3Status status[] = {fmi3OK, fmi3Warning, fmi3Error};
    Instance *in = (Instance *)env;
    const char *category = fmu_log_category(&in->fmu, level);
    if (in->logger && category) in->logger(in->env, status[level], category, message);
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
    in = (Instance *)fmu_instantiate(sizeof *in, &FMI3, name, is_cs, loggingOn, log_message);
    if (in) {
        in->env = env;
        in->logger = logger;
    }
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

void fmi3FreeInstance(fmi3Instance instance) { fmu_free(FMU(instance)); }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
    (void)nCategories;
    (void)categories;
    return STATUS(fmu_set_debug_logging(FMU(instance), __func__, loggingOn));
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    (void)stopTimeDefined;
    (void)stopTime;
    return STATUS(fmu_setup_experiment(FMU(instance), __func__, toleranceDefined, tolerance, startTime)
                  || fmu_enter_initialization_mode(FMU(instance), __func__));
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    return STATUS(fmu_exit_initialization_mode(FMU(instance), __func__));
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance) { return STATUS(fmu_enter_event_mode(FMU(instance), __func__)); }
fmi3Status fmi3Terminate(fmi3Instance instance) { return STATUS(fmu_terminate(FMU(instance), __func__)); }
fmi3Status fmi3Reset(fmi3Instance instance) { return STATUS(fmu_reset(FMU(instance), __func__)); }

/* ------------------------------------------------------------ variables */

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 values[],
                          size_t nValues) {
    return STATUS(fmu_get_reals(FMU(instance), __func__, vr, nvr, values, nValues));
}

fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Int32 values[],
                        size_t nValues) {
    return STATUS(fmu_get_integers(FMU(instance), __func__, vr, nvr, values, nValues));
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3Float64 values[],
                          size_t nValues) {
    return STATUS(fmu_set_reals(FMU(instance), __func__, vr, nvr, values, nValues));
}

fmi3Status fmi3SetInt32(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3Int32 values[],
                        size_t nValues) {
    return STATUS(fmu_set_integers(FMU(instance), __func__, vr, nvr, values, nValues));
}

fmi3Status fmi3GetInt64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Int64 values[],
                        size_t nValues) {
    return STATUS(fmu_get_enums(FMU(instance), __func__, vr, nvr, values, nValues));
}

fmi3Status fmi3SetInt64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3Int64 values[],
                        size_t nValues) {
    return STATUS(fmu_set_enums(FMU(instance), __func__, vr, nvr, values, nValues));
}

/* The model has no variables of the other types: any non-empty access is an error. */
#define NO_SUCH_TYPE(NAME, CTYPE, CONST)                                                                            \
    fmi3Status NAME(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, CONST CTYPE values[],        \
                    size_t nValues) {                                                                             \
        (void)vr;                                                                                                 \
        (void)values;                                                                                             \
        (void)nValues;                                                                                            \
        return STATUS(fmu_no_such_type(FMU(instance), #NAME, FMU_ANY, nvr, "the model has no variables of this type")); \
    }
NO_SUCH_TYPE(fmi3GetFloat32, fmi3Float32, )
NO_SUCH_TYPE(fmi3GetInt8, fmi3Int8, )
NO_SUCH_TYPE(fmi3GetUInt8, fmi3UInt8, )
NO_SUCH_TYPE(fmi3GetInt16, fmi3Int16, )
NO_SUCH_TYPE(fmi3GetUInt16, fmi3UInt16, )
NO_SUCH_TYPE(fmi3GetUInt32, fmi3UInt32, )
NO_SUCH_TYPE(fmi3GetUInt64, fmi3UInt64, )
NO_SUCH_TYPE(fmi3GetBoolean, fmi3Boolean, )
NO_SUCH_TYPE(fmi3GetString, fmi3String, )
NO_SUCH_TYPE(fmi3SetFloat32, fmi3Float32, const)
NO_SUCH_TYPE(fmi3SetInt8, fmi3Int8, const)
NO_SUCH_TYPE(fmi3SetUInt8, fmi3UInt8, const)
NO_SUCH_TYPE(fmi3SetInt16, fmi3Int16, const)
NO_SUCH_TYPE(fmi3SetUInt16, fmi3UInt16, const)
NO_SUCH_TYPE(fmi3SetUInt32, fmi3UInt32, const)
NO_SUCH_TYPE(fmi3SetUInt64, fmi3UInt64, const)
NO_SUCH_TYPE(fmi3SetBoolean, fmi3Boolean, const)
NO_SUCH_TYPE(fmi3SetString, fmi3String, const)

static fmi3Status unsupported(fmi3Instance instance, const char *function) {
    return STATUS(fmu_refuse(FMU(instance), function, "not supported by this FMU"));
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
    return STATUS(fmu_get_fmu_state(FMU(instance), __func__, s));
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState s) {
    return STATUS(fmu_set_fmu_state(FMU(instance), __func__, s));
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *s) {
    return STATUS(fmu_free_fmu_state(FMU(instance), __func__, s));
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState s, size_t *size) {
    (void)s;
    return STATUS(fmu_serialized_fmu_state_size(FMU(instance), __func__, size));
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState s, fmi3Byte bytes[], size_t size) {
    return STATUS(fmu_serialize_fmu_state(FMU(instance), __func__, s, bytes, size));
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte bytes[], size_t size, fmi3FMUState *s) {
    return STATUS(fmu_deserialize_fmu_state(FMU(instance), __func__, bytes, size, s));
}

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    return STATUS(fmu_directional_derivative(FMU(instance), __func__, unknowns, nUnknowns, knowns, nKnowns, seed, nSeed,
                                             sensitivity, nSensitivity));
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
    int changed, next_defined;
    double next;
    if (fmu_update_discrete_states(FMU(instance), __func__, &changed, &next_defined, &next)) return fmi3Error;
    *valuesOfContinuousStatesChanged = changed ? fmi3True : fmi3False;
    *discreteStatesNeedUpdate = fmi3False;
    *terminateSimulation = fmi3False;
    *nominalsOfContinuousStatesChanged = fmi3False;
    *nextEventTimeDefined = next_defined ? fmi3True : fmi3False;
    *nextEventTime = next;
    return fmi3OK;
}

/* ------------------------------------------------------------ Model Exchange */

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    return STATUS(fmu_enter_continuous_time_mode(FMU(instance), __func__));
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint;
    if (fmu_completed_integrator_step(FMU(instance), __func__)) return fmi3Error;
    *enterEventMode = fmi3False;
    *terminateSimulation = fmi3False;
    return fmi3OK;
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    return STATUS(fmu_set_time(FMU(instance), __func__, time));
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 x[], size_t nx) {
    return STATUS(fmu_set_continuous_states(FMU(instance), __func__, x, nx));
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 dx[], size_t nx) {
    return STATUS(fmu_get_derivatives(FMU(instance), __func__, dx, nx));
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 z[], size_t nz) {
    return STATUS(fmu_get_event_indicators(FMU(instance), __func__, z, nz));
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 x[], size_t nx) {
    return STATUS(fmu_get_continuous_states(FMU(instance), __func__, x, nx));
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t nx) {
    return STATUS(fmu_get_nominals(FMU(instance), __func__, nominals, nx));
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *n) {
    if (!fmu_allowed(FMU(instance), __func__, FMU_ANY)) return fmi3Error;
    *n = PAM_NZ;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *n) {
    if (!fmu_allowed(FMU(instance), __func__, FMU_ANY)) return fmi3Error;
    *n = PAM_NX;
    return fmi3OK;
}

/* ------------------------------------------------------------ Co-Simulation */

fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    return fmu_allowed(FMU(instance), __func__, FMU_STEP) && FMU(instance)->is_cs ? fmi3OK : fmi3Error;
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
    int rc = fmu_do_step(FMU(instance), __func__, currentCommunicationPoint, communicationStepSize);
    (void)noSetFMUStatePriorToCurrentPoint;
    if (rc == FMU_STEP_REFUSED) return fmi3Error;
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = fmi3False;
    *lastSuccessfulTime = FMU(instance)->core.time_s; /* a refused step leaves it where it was */
    return STATUS(rc);
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime) {
    (void)clockReference;
    (void)activationTime;
    return unsupported(instance, "fmi3ActivateModelPartition");
}
