/* FMI 2.0 Model Exchange and Co-Simulation interface: translates the calls to fmi_shell. */
#include <string.h>

#include "fmi2Functions.h"
#include "fmi_shell.h"

typedef struct {
    FmuInstance fmu; /* first, so that a component is an FmuInstance */
    fmi2CallbackFunctions cb;
} Instance;

static const FmuFlavour FMI2 = {.standard = "FMI 2.0",
                                .real_type = "Real",
                                .integer_type = "Integer",
                                .differentiable = "Real variables",
                                .time_is_vr0 = 0,
                                .enums_are_int64 = 0,
                                .states_evaluate_in = 0,
                                .derivatives_evaluate_in = FMU_INIT | FMU_EVENT | FMU_CONT | FMU_TERMINATED};

#define FMU(c) ((FmuInstance *)(c))
#define STATUS(rc) ((rc) ? fmi2Error : fmi2OK)

static void log_message(void *env, int level, const char *message) {
    static const fmi2Status status[] = {fmi2OK, fmi2Warning, fmi2Error};
    Instance *in = (Instance *)env;
    const char *category = fmu_log_category(&in->fmu, level);
    if (in->cb.logger && category)
        in->cb.logger(in->cb.componentEnvironment, in->fmu.name, status[level], category, "%s", message);
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
    in = (Instance *)fmu_instantiate(sizeof *in, &FMI2, instanceName, fmuType == fmi2CoSimulation, loggingOn,
                                     log_message);
    if (in) in->cb = *functions;
    return in;
}

void fmi2FreeInstance(fmi2Component c) { fmu_free(FMU(c)); }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t n, const fmi2String cats[]) {
    (void)n;
    (void)cats;
    return STATUS(fmu_set_debug_logging(FMU(c), __func__, loggingOn));
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    (void)stopTimeDefined;
    (void)stopTime;
    return STATUS(fmu_setup_experiment(FMU(c), __func__, toleranceDefined, tolerance, startTime));
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    return STATUS(fmu_enter_initialization_mode(FMU(c), __func__));
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    return STATUS(fmu_exit_initialization_mode(FMU(c), __func__));
}

fmi2Status fmi2Terminate(fmi2Component c) { return STATUS(fmu_terminate(FMU(c), __func__)); }
fmi2Status fmi2Reset(fmi2Component c) { return STATUS(fmu_reset(FMU(c), __func__)); }

/* ------------------------------------------------------------ variables */

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    return STATUS(fmu_get_reals(FMU(c), __func__, vr, nvr, value, nvr));
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
    return STATUS(fmu_get_integers(FMU(c), __func__, vr, nvr, value, nvr));
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
    (void)vr;
    (void)value;
    return STATUS(fmu_no_such_type(FMU(c), __func__, FMU_RUNNING, nvr, "the model has no Boolean variables"));
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
    (void)vr;
    (void)value;
    return STATUS(fmu_no_such_type(FMU(c), __func__, FMU_RUNNING, nvr, "the model has no String variables"));
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    return STATUS(fmu_set_reals(FMU(c), __func__, vr, nvr, value, nvr));
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[]) {
    return STATUS(fmu_set_integers(FMU(c), __func__, vr, nvr, value, nvr));
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[]) {
    (void)vr;
    (void)value;
    return STATUS(fmu_no_such_type(FMU(c), __func__, FMU_ANY, nvr, "the model has no Boolean variables"));
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
    (void)vr;
    (void)value;
    return STATUS(fmu_no_such_type(FMU(c), __func__, FMU_ANY, nvr, "the model has no String variables"));
}

/* ------------------------------------------------------------ FMU state */

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) { return STATUS(fmu_get_fmu_state(FMU(c), __func__, s)); }
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { return STATUS(fmu_set_fmu_state(FMU(c), __func__, s)); }

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) {
    return STATUS(fmu_free_fmu_state(FMU(c), __func__, s));
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *size) {
    (void)s;
    return STATUS(fmu_serialized_fmu_state_size(FMU(c), __func__, size));
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte bytes[], size_t size) {
    return STATUS(fmu_serialize_fmu_state(FMU(c), __func__, s, bytes, size));
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate *s) {
    return STATUS(fmu_deserialize_fmu_state(FMU(c), __func__, bytes, size, s));
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown, const fmi2Real dvKnown[],
                                        fmi2Real dvUnknown[]) {
    return STATUS(fmu_directional_derivative(FMU(c), __func__, vUnknown_ref, nUnknown, vKnown_ref, nKnown, dvKnown,
                                             nKnown, dvUnknown, nUnknown));
}

/* ------------------------------------------------------------ Model Exchange */

fmi2Status fmi2EnterEventMode(fmi2Component c) { return STATUS(fmu_enter_event_mode(FMU(c), __func__)); }

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) {
    int changed, next_defined;
    double next;
    if (fmu_update_discrete_states(FMU(c), __func__, &changed, &next_defined, &next)) return fmi2Error;
    info->valuesOfContinuousStatesChanged = changed ? fmi2True : fmi2False;
    info->newDiscreteStatesNeeded = fmi2False;
    info->terminateSimulation = fmi2False;
    info->nominalsOfContinuousStatesChanged = fmi2False;
    info->nextEventTimeDefined = next_defined ? fmi2True : fmi2False;
    info->nextEventTime = next;
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) {
    return STATUS(fmu_enter_continuous_time_mode(FMU(c), __func__));
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint;
    if (fmu_completed_integrator_step(FMU(c), __func__)) return fmi2Error;
    *enterEventMode = fmi2False;
    *terminateSimulation = fmi2False;
    return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) { return STATUS(fmu_set_time(FMU(c), __func__, time)); }

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
    return STATUS(fmu_set_continuous_states(FMU(c), __func__, x, nx));
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real dx[], size_t nx) {
    return STATUS(fmu_get_derivatives(FMU(c), __func__, dx, nx));
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real z[], size_t nz) {
    return STATUS(fmu_get_event_indicators(FMU(c), __func__, z, nz));
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
    return STATUS(fmu_get_continuous_states(FMU(c), __func__, x, nx));
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[], size_t nx) {
    return STATUS(fmu_get_nominals(FMU(c), __func__, x_nominal, nx));
}

/* ------------------------------------------------------------ Co-Simulation */

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    return STATUS(fmu_refuse(FMU(c), __func__, "not supported (inputs are held over a step)"));
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    return STATUS(fmu_refuse(FMU(c), __func__, "not supported"));
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentCommunicationPoint) {
    (void)noSetFMUStatePriorToCurrentCommunicationPoint;
    return STATUS(fmu_do_step(FMU(c), __func__, currentCommunicationPoint, communicationStepSize));
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    return STATUS(fmu_refuse(FMU(c), __func__, "steps are synchronous and cannot be cancelled"));
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)c;
    (void)s;
    (void)value;
    return fmi2Discard;
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    if (!c) return fmi2Error;
    if (s == fmi2LastSuccessfulTime) {
        *value = FMU(c)->core.time_s;
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
