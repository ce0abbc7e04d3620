/* Generic FMI 3.0 wrapper (Co-Simulation and Model Exchange) around the simulation core of
 * model_core.h, the same core as the FMI 2.0 wrapper: an FMI 3.0 build computes the same
 * numbers as an FMI 2.0 build of the same model. Nothing here is specific to one model.
 *
 * Value references are unique across types (FMI 3.0): the Float64 variables keep the FMI 2.0
 * layout 0 .. VR_END-1, then come the independent variable `time` (VR_TIME) and the Int32
 * constants (VR_C0 ...).
 */
#include "fmi3Functions.h"
#include "model_core.h"

#define VR_TIME VR_END
#define VR_C0 (VR_END + 1)

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
} Host3;

static void host_log3(Comp *c, int status, const char *category, const char *message) {
    const Host3 *h = (const Host3 *)c->host;
    if (h && h->log) h->log(h->env, (fmi3Status)status, category, message);
}

static fmi3Instance instantiate(fmi3String instanceName, fmi3String token, fmi3Boolean loggingOn,
                                fmi3InstanceEnvironment env, fmi3LogMessageCallback logMessage, int is_me) {
    Comp *c;
    Host3 *h;
    if (!token || strcmp(token, MODEL_GUID) != 0) {
        if (logMessage) {
            char msg[256];
            snprintf(msg, sizeof msg, "instantiation token %s does not match this binary (%s)",
                     token ? token : "(null)", MODEL_GUID);
            logMessage(env, fmi3Error, "logStatusError", msg);
        }
        return NULL;
    }
    h = (Host3 *)malloc(sizeof *h);
    if (!h) return NULL;
    h->env = env;
    h->log = logMessage;
    c = core_new(instanceName, is_me, host_log3, h, loggingOn);
    if (!c) { free(h); return NULL; }
    return c;
}

static fmi3Status unsupported(fmi3Instance instance, const char *what) {
    logmsg((Comp *)instance, ST_ERROR, "logStatusError", "%s is not supported by this FMU", what);
    return fmi3Error;
}

/* ---- Common functions --------------------------------------------------------------------- */
const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
    (void)nCategories; (void)categories;
    ((Comp *)instance)->logging = loggingOn;
    return fmi3OK;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage) {
    (void)resourcePath; (void)visible;
    return instantiate(instanceName, instantiationToken, loggingOn, instanceEnvironment, logMessage, 1);
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)resourcePath; (void)visible; (void)eventModeUsed; (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables; (void)nRequiredIntermediateVariables; (void)intermediateUpdate;
    return instantiate(instanceName, instantiationToken, loggingOn, instanceEnvironment, logMessage, 0);
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instanceName; (void)instantiationToken; (void)resourcePath; (void)visible; (void)loggingOn;
    (void)clockUpdate; (void)lockPreemption; (void)unlockPreemption;
    if (logMessage) logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                               "this FMU does not implement Scheduled Execution");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance) {
    Comp *c = (Comp *)instance;
    if (!c) return;
    free(c->host);
    core_free(c);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    Comp *c = (Comp *)instance;
    (void)toleranceDefined; (void)tolerance; (void)stopTimeDefined; (void)stopTime;
    core_setup(c, startTime);
    c->phase = INITIALIZATION;
    return fmi3OK;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    core_exit_initialization((Comp *)instance);
    return fmi3OK;
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance) { (void)instance; return fmi3OK; }
fmi3Status fmi3Terminate(fmi3Instance instance) { ((Comp *)instance)->phase = TERMINATED; return fmi3OK; }
fmi3Status fmi3Reset(fmi3Instance instance) { set_defaults((Comp *)instance); return fmi3OK; }

/* ---- Getting and setting values ------------------------------------------------------------ */
fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, fmi3Float64 values[], size_t nValues) {
    Comp *c = (Comp *)instance;
    size_t i;
    if (nValues != nValueReferences) return unsupported(instance, "fmi3GetFloat64 of arrays");
    for (i = 0; i < nValueReferences; i++) {
        if (valueReferences[i] == (fmi3ValueReference)VR_TIME) { values[i] = c->t; continue; }
        if (core_get_real(c, valueReferences[i], &values[i], "fmi3GetFloat64") != ST_OK) return fmi3Error;
    }
    return fmi3OK;
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, const fmi3Float64 values[], size_t nValues) {
    size_t i;
    if (nValues != nValueReferences) return unsupported(instance, "fmi3SetFloat64 of arrays");
    for (i = 0; i < nValueReferences; i++)
        if (core_set_real((Comp *)instance, valueReferences[i], values[i], "fmi3SetFloat64") != ST_OK) return fmi3Error;
    return fmi3OK;
}

fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        fmi3Int32 values[], size_t nValues) {
    size_t i;
    (void)nValues;
    for (i = 0; i < nValueReferences; i++) {
        fmi3ValueReference r = valueReferences[i];
        if (r < (fmi3ValueReference)VR_C0 || r >= (fmi3ValueReference)(VR_C0 + N_C_)) {
            logmsg((Comp *)instance, ST_ERROR, "logStatusError", "fmi3GetInt32: unknown value reference %u", r);
            return fmi3Error;
        }
        values[i] = C_VALUES[r - VR_C0];
    }
    return fmi3OK;
}

fmi3Status fmi3SetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        const fmi3Int32 values[], size_t nValues) {
    (void)valueReferences; (void)values; (void)nValues;
    if (nValueReferences == 0) return fmi3OK;
    logmsg((Comp *)instance, ST_ERROR, "logStatusError",
           "Int32 variables of this FMU are structural constants; rebuild the FMU to change them");
    return fmi3Error;
}

/* This FMU has no variables of the other types. */
#define NO_VARIABLES(NAME, T) \
    fmi3Status NAME(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, \
                    T values[], size_t nValues) { \
        (void)valueReferences; (void)values; (void)nValues; \
        if (nValueReferences == 0) return fmi3OK; \
        return unsupported(instance, #NAME " (the FMU has no such variables)"); \
    }
NO_VARIABLES(fmi3GetFloat32, fmi3Float32)
NO_VARIABLES(fmi3GetInt8, fmi3Int8)
NO_VARIABLES(fmi3GetUInt8, fmi3UInt8)
NO_VARIABLES(fmi3GetInt16, fmi3Int16)
NO_VARIABLES(fmi3GetUInt16, fmi3UInt16)
NO_VARIABLES(fmi3GetUInt32, fmi3UInt32)
NO_VARIABLES(fmi3GetInt64, fmi3Int64)
NO_VARIABLES(fmi3GetUInt64, fmi3UInt64)
NO_VARIABLES(fmi3GetBoolean, fmi3Boolean)
NO_VARIABLES(fmi3GetString, fmi3String)
NO_VARIABLES(fmi3SetFloat32, const fmi3Float32)
NO_VARIABLES(fmi3SetInt8, const fmi3Int8)
NO_VARIABLES(fmi3SetUInt8, const fmi3UInt8)
NO_VARIABLES(fmi3SetInt16, const fmi3Int16)
NO_VARIABLES(fmi3SetUInt16, const fmi3UInt16)
NO_VARIABLES(fmi3SetUInt32, const fmi3UInt32)
NO_VARIABLES(fmi3SetInt64, const fmi3Int64)
NO_VARIABLES(fmi3SetUInt64, const fmi3UInt64)
NO_VARIABLES(fmi3SetBoolean, const fmi3Boolean)
NO_VARIABLES(fmi3SetString, const fmi3String)

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         size_t valueSizes[], fmi3Binary values[], size_t nValues) {
    (void)valueReferences; (void)valueSizes; (void)values; (void)nValues;
    return nValueReferences == 0 ? fmi3OK : unsupported(instance, "fmi3GetBinary");
}
fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         const size_t valueSizes[], const fmi3Binary values[], size_t nValues) {
    (void)valueReferences; (void)valueSizes; (void)values; (void)nValues;
    return nValueReferences == 0 ? fmi3OK : unsupported(instance, "fmi3SetBinary");
}
fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        fmi3Clock values[]) {
    (void)valueReferences; (void)values;
    return nValueReferences == 0 ? fmi3OK : unsupported(instance, "fmi3GetClock");
}
fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        const fmi3Clock values[]) {
    (void)valueReferences; (void)values;
    return nValueReferences == 0 ? fmi3OK : unsupported(instance, "fmi3SetClock");
}

/* ---- Variable dependencies: given in modelDescription.xml ---------------------------------- */
fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference,
                                               size_t *nDependencies) {
    (void)valueReference; (void)nDependencies;
    return unsupported(instance, "fmi3GetNumberOfVariableDependencies (see ModelStructure in modelDescription.xml)");
}
fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies) {
    (void)dependent; (void)elementIndicesOfDependent; (void)independents; (void)elementIndicesOfIndependents;
    (void)dependencyKinds; (void)nDependencies;
    return unsupported(instance, "fmi3GetVariableDependencies (see ModelStructure in modelDescription.xml)");
}

/* ---- FMU state ------------------------------------------------------------------------------- */
fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    Snapshot *s = *FMUState ? (Snapshot *)*FMUState : (Snapshot *)calloc(1, sizeof(Snapshot));
    if (!s) return fmi3Error;
    core_snapshot((Comp *)instance, s);
    *FMUState = s;
    return fmi3OK;
}
fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState) {
    if (!FMUState) return fmi3Error;
    core_restore((Comp *)instance, (const Snapshot *)FMUState);
    return fmi3OK;
}
fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    (void)instance;
    if (FMUState && *FMUState) { free(*FMUState); *FMUState = NULL; }
    return fmi3OK;
}
fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t *size) {
    (void)instance; (void)FMUState;
    *size = core_serialized_size();
    return fmi3OK;
}
fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[], size_t size) {
    (void)instance;
    return core_serialize((const Snapshot *)FMUState, (unsigned char *)serializedState, size) == 0 ? fmi3OK : fmi3Error;
}
fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState *FMUState) {
    Snapshot tmp, *s;
    if (core_deserialize((Comp *)instance, (const unsigned char *)serializedState, size, &tmp) != 0) return fmi3Error;
    s = *FMUState ? (Snapshot *)*FMUState : (Snapshot *)malloc(sizeof(Snapshot));
    if (!s) return fmi3Error;
    *s = tmp;
    *FMUState = s;
    return fmi3OK;
}

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed; (void)sensitivity;
    (void)nSensitivity;
    return unsupported(instance, "fmi3GetDirectionalDerivative");
}
fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed; (void)sensitivity;
    (void)nSensitivity;
    return unsupported(instance, "fmi3GetAdjointDerivative");
}

/* ---- Configuration mode and clocks: no structural parameters, no clocks --------------------- */
fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) { return unsupported(instance, "fmi3EnterConfigurationMode"); }
fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) { return unsupported(instance, "fmi3ExitConfigurationMode"); }
fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[]) {
    (void)valueReferences; (void)nValueReferences; (void)intervals; (void)qualifiers;
    return unsupported(instance, "fmi3GetIntervalDecimal");
}
fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[]) {
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions; (void)qualifiers;
    return unsupported(instance, "fmi3GetIntervalFraction");
}
fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Float64 shifts[]) {
    (void)valueReferences; (void)nValueReferences; (void)shifts;
    return unsupported(instance, "fmi3GetShiftDecimal");
}
fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[]) {
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    return unsupported(instance, "fmi3GetShiftFraction");
}
fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, const fmi3Float64 intervals[]) {
    (void)valueReferences; (void)nValueReferences; (void)intervals;
    return unsupported(instance, "fmi3SetIntervalDecimal");
}
fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]) {
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    return unsupported(instance, "fmi3SetIntervalFraction");
}
fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Float64 shifts[]) {
    (void)valueReferences; (void)nValueReferences; (void)shifts;
    return unsupported(instance, "fmi3SetShiftDecimal");
}
fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]) {
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    return unsupported(instance, "fmi3SetShiftFraction");
}
fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) { (void)instance; return fmi3OK; }
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime) {
    (void)instance;
    *discreteStatesNeedUpdate = fmi3False; *terminateSimulation = fmi3False;
    *nominalsOfContinuousStatesChanged = fmi3False; *valuesOfContinuousStatesChanged = fmi3False;
    *nextEventTimeDefined = fmi3False; *nextEventTime = 0.0;
    return fmi3OK;
}

/* ---- Model Exchange ---------------------------------------------------------------------------- */
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) { (void)instance; return fmi3OK; }
fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation) {
    (void)instance; (void)noSetFMUStatePriorToCurrentPoint;
    *enterEventMode = fmi3False; *terminateSimulation = fmi3False;
    return fmi3OK;
}
fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    Comp *c = (Comp *)instance; c->t = time; c->y_dirty = c->xdot_dirty = 1; c->k1_valid = 0; return fmi3OK;
}
fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[], size_t n) {
    return core_set_states((Comp *)instance, continuousStates, n) == ST_OK ? fmi3OK : fmi3Error;
}
fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[], size_t n) {
    return core_get_derivatives((Comp *)instance, derivatives, n) == ST_OK ? fmi3OK : fmi3Error;
}
fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[], size_t n) {
    (void)instance; (void)eventIndicators;
    return n == 0 ? fmi3OK : fmi3Error;
}
fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[], size_t n) {
    return core_get_states((Comp *)instance, continuousStates, n) == ST_OK ? fmi3OK : fmi3Error;
}
fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t n) {
    return core_get_nominals((Comp *)instance, nominals, n) == ST_OK ? fmi3OK : fmi3Error;
}
fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators) {
    (void)instance; *nEventIndicators = 0; return fmi3OK;
}
fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates) {
    (void)instance; *nContinuousStates = (size_t)N_X; return fmi3OK;
}

/* ---- Co-Simulation --------------------------------------------------------------------------- */
fmi3Status fmi3EnterStepMode(fmi3Instance instance) { (void)instance; return fmi3OK; }

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[],
                                    size_t nValues) {
    (void)valueReferences; (void)orders; (void)values; (void)nValues;
    return nValueReferences == 0 ? fmi3OK : unsupported(instance, "fmi3GetOutputDerivatives");
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    Comp *c = (Comp *)instance;
    int st;
    (void)noSetFMUStatePriorToCurrentPoint;
    st = core_do_step(c, currentCommunicationPoint, communicationStepSize, "fmi3DoStep");
    if (eventHandlingNeeded) *eventHandlingNeeded = fmi3False;
    if (terminateSimulation) *terminateSimulation = fmi3False;
    if (earlyReturn) *earlyReturn = fmi3False;
    if (lastSuccessfulTime) *lastSuccessfulTime = c->t;
    return st == ST_OK ? fmi3OK : fmi3Error;
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime) {
    (void)clockReference; (void)activationTime;
    return unsupported(instance, "fmi3ActivateModelPartition");
}

/* ---- Output buffer extension (not part of FMI 3.0) ----------------------------------------- */
FMI3_Export size_t twin_fmi3OutputBufferWidth(void) { return (size_t)N_Y; }

/* Copies up to `capacity` samples of the last doStep (N_Y doubles each, in output value
 * reference order) into dst and returns how many samples the buffer held. */
FMI3_Export size_t twin_fmi3GetOutputBuffer(fmi3Instance instance, double *dst, size_t capacity) {
    return core_output_buffer((const Comp *)instance, dst, capacity);
}
