/*
 * fmi3_slave.c: the FMI 3.0 Co-Simulation API over core.c and a model (slave.h).
 *
 * Scalar variables of every FMI 3.0 value type except Clock; no event mode, no early return,
 * no Model Exchange or Scheduled Execution (those entry points exist, as the standard
 * requires, and fail with a message).  When the model ends the experiment inside a step,
 * fmi3DoStep returns fmi3OK with terminateSimulation = fmi3True and lastSuccessfulTime the
 * time it ended at.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "core.h"

typedef struct {
    Core core;
    char *name;
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    fmi3Boolean logging_on;
} Instance;

static void log_msg(const Instance *inst, fmi3Status status, const char *fmt, ...)
{
    char text[512];
    va_list ap;
    const char *category = status >= fmi3Error ? "logStatusError"
                           : status == fmi3Discard ? "logStatusDiscard" : "logEvents";

    if (inst == NULL || inst->log == NULL)
        return;
    if (status < fmi3Discard && !inst->logging_on)
        return;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    inst->log(inst->env, status, category, text);
}

#define FAIL(inst, ...) (log_msg((inst), fmi3Error, __VA_ARGS__), fmi3Error)

static Instance *enter(fmi3Instance c, const char *fn, int allowed)
{
    Instance *inst = (Instance *)c;
    if (inst == NULL)
        return NULL;
    if (!((int)inst->core.phase & allowed)) {
        log_msg(inst, fmi3Error, "%s: not allowed in %s", fn, phase_name(inst->core.phase));
        return NULL;
    }
    return inst;
}

/* ---- version, logging, life cycle ------------------------------------------------------ */

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[])
{
    Instance *inst = enter(instance, "fmi3SetDebugLogging", PH_ANY);
    (void)nCategories;
    (void)categories;
    if (inst == NULL)
        return fmi3Error;
    inst->logging_on = loggingOn;
    return fmi3OK;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage)
{
    (void)instanceName; (void)instantiationToken; (void)resourcePath; (void)visible; (void)loggingOn;
    if (logMessage != NULL)
        logMessage(instanceEnvironment, fmi3Error, "logStatusError", "Model Exchange is not provided");
    return NULL;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate)
{
    Instance *inst;
    (void)visible; (void)earlyReturnAllowed; (void)requiredIntermediateVariables;
    (void)nRequiredIntermediateVariables; (void)intermediateUpdate;

    if (instanceName == NULL || instanceName[0] == '\0') {
        if (logMessage != NULL)
            logMessage(instanceEnvironment, fmi3Error, "logStatusError", "missing instance name");
        return NULL;
    }
    if (instantiationToken == NULL || strcmp(instantiationToken, MODEL_TOKEN) != 0) {
        if (logMessage != NULL)
            logMessage(instanceEnvironment, fmi3Error, "logStatusError", "wrong instantiationToken");
        return NULL;
    }
    if (eventModeUsed) {
        if (logMessage != NULL)
            logMessage(instanceEnvironment, fmi3Error, "logStatusError", "event mode is not provided (hasEventMode=false)");
        return NULL;
    }
    inst = calloc(1, sizeof *inst);
    if (inst == NULL)
        return NULL;
    inst->env = instanceEnvironment;
    inst->log = logMessage;
    inst->logging_on = loggingOn;
    inst->name = malloc(strlen(instanceName) + 1);
    if (inst->name == NULL || core_create(&inst->core, resourcePath) != 0) {
        free(inst->name);
        free(inst);
        return NULL;
    }
    strcpy(inst->name, instanceName);
    return inst;
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage,
                                               fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption)
{
    (void)instanceName; (void)instantiationToken; (void)resourcePath; (void)visible; (void)loggingOn;
    (void)clockUpdate; (void)lockPreemption; (void)unlockPreemption;
    if (logMessage != NULL)
        logMessage(instanceEnvironment, fmi3Error, "logStatusError", "Scheduled Execution is not provided");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance)
{
    Instance *inst = (Instance *)instance;
    if (inst == NULL)
        return;
    core_destroy(&inst->core);
    free(inst->name);
    free(inst);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime)
{
    Instance *inst = enter(instance, "fmi3EnterInitializationMode", PH_INSTANTIATED);
    (void)toleranceDefined;
    (void)tolerance;
    if (inst == NULL)
        return fmi3Error;
    if (stopTimeDefined && stopTime < startTime)
        return FAIL(inst, "fmi3EnterInitializationMode: stop time %g is before start time %g", stopTime, startTime);
    inst->core.time = startTime;
    inst->core.stop_defined = stopTimeDefined;
    inst->core.stop_time = stopTime;
    inst->core.phase = PH_INIT;
    return fmi3OK;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance)
{
    char msg[256];
    Instance *inst = enter(instance, "fmi3ExitInitializationMode", PH_INIT);
    if (inst == NULL)
        return fmi3Error;
    if (core_exit_initialization(&inst->core, msg, sizeof msg) != 0)
        return FAIL(inst, "fmi3ExitInitializationMode: %s", msg);
    return fmi3OK;
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance)
{
    return FAIL((Instance *)instance, "fmi3EnterEventMode: event mode is not provided");
}

fmi3Status fmi3Terminate(fmi3Instance instance)
{
    Instance *inst = enter(instance, "fmi3Terminate", PH_STEP | PH_ERROR);
    if (inst == NULL)
        return fmi3Error;
    inst->core.phase = PH_TERMINATED;
    return fmi3OK;
}

fmi3Status fmi3Reset(fmi3Instance instance)
{
    Instance *inst = enter(instance, "fmi3Reset", PH_ANY);
    if (inst == NULL)
        return fmi3Error;
    core_reset(&inst->core);
    return fmi3OK;
}

/* ---- values ---------------------------------------------------------------------------- */

static const VarInfo *typed(Instance *inst, const char *fn, fmi3ValueReference vr, ValueType a, ValueType b)
{
    const VarInfo *v = core_lookup(vr);
    if (v == NULL) {
        log_msg(inst, fmi3Error, "%s: unknown value reference %u", fn, vr);
        return NULL;
    }
    if (v->type != a && v->type != b) {
        log_msg(inst, fmi3Error, "%s: value reference %u (%s) has another type", fn, vr, v->name);
        return NULL;
    }
    return v;
}

static const VarInfo *settable(Instance *inst, const char *fn, fmi3ValueReference vr, ValueType a, ValueType b)
{
    const char *why;
    const VarInfo *v = typed(inst, fn, vr, a, b);
    if (v == NULL)
        return NULL;
    why = core_why_not_settable(&inst->core, v);
    if (why != NULL) {
        log_msg(inst, fmi3Error, "%s: %s cannot be set in %s: %s", fn, v->name, phase_name(inst->core.phase), why);
        return NULL;
    }
    return v;
}

#define GETTABLE (PH_INSTANTIATED | PH_INIT | PH_STEP | PH_TERMINATED | PH_ERROR)
#define SETTABLE (PH_INSTANTIATED | PH_INIT | PH_STEP)

/* Every variable is a scalar, so nValues must equal nValueReferences. */
#define SCALARS(inst, fn, nvr, nValues) \
    if ((nValues) != (nvr)) \
        return FAIL((inst), "%s: %zu values for %zu scalar variables", (fn), (size_t)(nValues), (size_t)(nvr))

#define ACCESSORS(Name, CType, VT_A, VT_B)                                                          \
fmi3Status fmi3Get##Name(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,           \
                         CType values[], size_t nValues)                                             \
{                                                                                                    \
    size_t i;                                                                                        \
    Instance *inst = enter(instance, "fmi3Get" #Name, GETTABLE);                                     \
    if (inst == NULL)                                                                                \
        return fmi3Error;                                                                            \
    SCALARS(inst, "fmi3Get" #Name, nvr, nValues);                                                    \
    core_refresh(&inst->core);                                                                       \
    for (i = 0; i < nvr; i++) {                                                                      \
        const VarInfo *v = typed(inst, "fmi3Get" #Name, vr[i], VT_A, VT_B);                          \
        if (v == NULL)                                                                               \
            return fmi3Error;                                                                        \
        values[i] = *(const CType *)core_field(&inst->core, v);                                      \
    }                                                                                                \
    return fmi3OK;                                                                                   \
}                                                                                                    \
fmi3Status fmi3Set##Name(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,           \
                         const CType values[], size_t nValues)                                       \
{                                                                                                    \
    size_t i;                                                                                        \
    Instance *inst = enter(instance, "fmi3Set" #Name, SETTABLE);                                     \
    if (inst == NULL)                                                                                \
        return fmi3Error;                                                                            \
    SCALARS(inst, "fmi3Set" #Name, nvr, nValues);                                                    \
    for (i = 0; i < nvr; i++) {                                                                      \
        const VarInfo *v = settable(inst, "fmi3Set" #Name, vr[i], VT_A, VT_B);                       \
        if (v == NULL)                                                                               \
            return fmi3Error;                                                                        \
        *(CType *)core_field(&inst->core, v) = values[i];                                            \
    }                                                                                                \
    inst->core.dirty = true;                                                                         \
    return fmi3OK;                                                                                   \
}

ACCESSORS(Float32, fmi3Float32, VT_FLOAT32, VT_FLOAT32)
ACCESSORS(Float64, fmi3Float64, VT_FLOAT64, VT_FLOAT64)
ACCESSORS(Int8, fmi3Int8, VT_INT8, VT_INT8)
ACCESSORS(UInt8, fmi3UInt8, VT_UINT8, VT_UINT8)
ACCESSORS(Int16, fmi3Int16, VT_INT16, VT_INT16)
ACCESSORS(UInt16, fmi3UInt16, VT_UINT16, VT_UINT16)
ACCESSORS(Int32, fmi3Int32, VT_INT32, VT_INT32)
ACCESSORS(UInt32, fmi3UInt32, VT_UINT32, VT_UINT32)
ACCESSORS(Int64, fmi3Int64, VT_INT64, VT_ENUMERATION)    /* enumerations are Int64 in FMI 3.0 */
ACCESSORS(UInt64, fmi3UInt64, VT_UINT64, VT_UINT64)
ACCESSORS(Boolean, fmi3Boolean, VT_BOOLEAN, VT_BOOLEAN)

fmi3Status fmi3GetString(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                         fmi3String values[], size_t nValues)
{
    size_t i;
    Instance *inst = enter(instance, "fmi3GetString", GETTABLE);
    if (inst == NULL)
        return fmi3Error;
    SCALARS(inst, "fmi3GetString", nvr, nValues);
    core_refresh(&inst->core);
    for (i = 0; i < nvr; i++) {
        const VarInfo *v = typed(inst, "fmi3GetString", vr[i], VT_STRING, VT_STRING);
        if (v == NULL)
            return fmi3Error;
        values[i] = (const char *)core_field(&inst->core, v);
    }
    return fmi3OK;
}

fmi3Status fmi3SetString(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                         const fmi3String values[], size_t nValues)
{
    size_t i;
    Instance *inst = enter(instance, "fmi3SetString", SETTABLE);
    if (inst == NULL)
        return fmi3Error;
    SCALARS(inst, "fmi3SetString", nvr, nValues);
    for (i = 0; i < nvr; i++) {
        const VarInfo *v = settable(inst, "fmi3SetString", vr[i], VT_STRING, VT_STRING);
        if (v == NULL)
            return fmi3Error;
        if (values[i] == NULL)
            return FAIL(inst, "fmi3SetString: NULL value for %s", v->name);
        if (strlen(values[i]) >= STRING_CAPACITY)
            return FAIL(inst, "fmi3SetString: %s takes at most %d characters", v->name, STRING_CAPACITY - 1);
        strcpy((char *)core_field(&inst->core, v), values[i]);
    }
    inst->core.dirty = true;
    return fmi3OK;
}

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                         size_t valueSizes[], fmi3Binary values[], size_t nValues)
{
    size_t i;
    Instance *inst = enter(instance, "fmi3GetBinary", GETTABLE);
    if (inst == NULL)
        return fmi3Error;
    SCALARS(inst, "fmi3GetBinary", nvr, nValues);
    core_refresh(&inst->core);
    for (i = 0; i < nvr; i++) {
        const VarInfo *v = typed(inst, "fmi3GetBinary", vr[i], VT_BINARY, VT_BINARY);
        const Bytes *b;
        if (v == NULL)
            return fmi3Error;
        b = (const Bytes *)core_field(&inst->core, v);
        valueSizes[i] = b->size;
        values[i] = b->data;
    }
    return fmi3OK;
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                         const size_t valueSizes[], const fmi3Binary values[], size_t nValues)
{
    size_t i;
    Instance *inst = enter(instance, "fmi3SetBinary", SETTABLE);
    if (inst == NULL)
        return fmi3Error;
    SCALARS(inst, "fmi3SetBinary", nvr, nValues);
    for (i = 0; i < nvr; i++) {
        const VarInfo *v = settable(inst, "fmi3SetBinary", vr[i], VT_BINARY, VT_BINARY);
        Bytes *b;
        if (v == NULL)
            return fmi3Error;
        if (valueSizes[i] > BINARY_CAPACITY)
            return FAIL(inst, "fmi3SetBinary: %s takes at most %d bytes", v->name, BINARY_CAPACITY);
        b = (Bytes *)core_field(&inst->core, v);
        b->size = valueSizes[i];
        if (valueSizes[i] > 0)
            memcpy(b->data, values[i], valueSizes[i]);
    }
    inst->core.dirty = true;
    return fmi3OK;
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, fmi3Clock values[])
{
    (void)vr; (void)nvr; (void)values;
    return FAIL((Instance *)instance, "fmi3GetClock: this FMU has no clocks");
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const fmi3Clock values[])
{
    (void)vr; (void)nvr; (void)values;
    return FAIL((Instance *)instance, "fmi3SetClock: this FMU has no clocks");
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference,
                                               size_t *nDependencies)
{
    (void)valueReference; (void)nDependencies;
    return FAIL((Instance *)instance, "fmi3GetNumberOfVariableDependencies is not provided");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies)
{
    (void)dependent; (void)elementIndicesOfDependent; (void)independents; (void)elementIndicesOfIndependents;
    (void)dependencyKinds; (void)nDependencies;
    return FAIL((Instance *)instance, "fmi3GetVariableDependencies is not provided");
}

/* ---- FMU state --------------------------------------------------------------------------- */

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    unsigned char *buffer;
    Instance *inst = enter(instance, "fmi3GetFMUState", PH_ANY);
    if (inst == NULL || FMUState == NULL)
        return fmi3Error;
    buffer = *FMUState != NULL ? (unsigned char *)*FMUState : malloc(core_state_size());
    if (buffer == NULL)
        return FAIL(inst, "fmi3GetFMUState: out of memory");
    core_save(&inst->core, buffer);
    *FMUState = buffer;
    return fmi3OK;
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState)
{
    Instance *inst = enter(instance, "fmi3SetFMUState", PH_ANY);
    if (inst == NULL || FMUState == NULL)
        return fmi3Error;
    core_restore(&inst->core, (const unsigned char *)FMUState);
    return fmi3OK;
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    Instance *inst = enter(instance, "fmi3FreeFMUState", PH_ANY);
    if (inst == NULL || FMUState == NULL)
        return fmi3Error;
    free(*FMUState);
    *FMUState = NULL;
    return fmi3OK;
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t *size)
{
    Instance *inst = enter(instance, "fmi3SerializedFMUStateSize", PH_ANY);
    (void)FMUState;
    if (inst == NULL || size == NULL)
        return fmi3Error;
    *size = core_state_size();
    return fmi3OK;
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[], size_t size)
{
    Instance *inst = enter(instance, "fmi3SerializeFMUState", PH_ANY);
    if (inst == NULL || FMUState == NULL)
        return fmi3Error;
    if (size != core_state_size())
        return FAIL(inst, "fmi3SerializeFMUState: size %zu, expected %zu", size, core_state_size());
    memcpy(serializedState, FMUState, size);
    return fmi3OK;
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState *FMUState)
{
    unsigned char *buffer;
    Instance *inst = enter(instance, "fmi3DeserializeFMUState", PH_ANY);
    if (inst == NULL || FMUState == NULL)
        return fmi3Error;
    if (size != core_state_size())
        return FAIL(inst, "fmi3DeserializeFMUState: size %zu, expected %zu", size, core_state_size());
    buffer = malloc(size);
    if (buffer == NULL)
        return FAIL(inst, "fmi3DeserializeFMUState: out of memory");
    memcpy(buffer, serializedState, size);
    *FMUState = buffer;
    return fmi3OK;
}

/* ---- not provided: derivatives, clocks, configuration, Model Exchange ------------------- */

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
{
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed;
    (void)sensitivity; (void)nSensitivity;
    return FAIL((Instance *)instance, "fmi3GetDirectionalDerivative is not provided");
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
{
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed;
    (void)sensitivity; (void)nSensitivity;
    return FAIL((Instance *)instance, "fmi3GetAdjointDerivative is not provided");
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance)
{
    return FAIL((Instance *)instance, "fmi3EnterConfigurationMode is not provided");
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance)
{
    return FAIL((Instance *)instance, "fmi3ExitConfigurationMode is not provided");
}

#define NO_CLOCKS(inst, fn) return FAIL((Instance *)(inst), "%s: this FMU has no clocks", (fn))

fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[])
{
    (void)valueReferences; (void)nValueReferences; (void)intervals; (void)qualifiers;
    NO_CLOCKS(instance, "fmi3GetIntervalDecimal");
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[])
{
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions; (void)qualifiers;
    NO_CLOCKS(instance, "fmi3GetIntervalFraction");
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Float64 shifts[])
{
    (void)valueReferences; (void)nValueReferences; (void)shifts;
    NO_CLOCKS(instance, "fmi3GetShiftDecimal");
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[])
{
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    NO_CLOCKS(instance, "fmi3GetShiftFraction");
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, const fmi3Float64 intervals[])
{
    (void)valueReferences; (void)nValueReferences; (void)intervals;
    NO_CLOCKS(instance, "fmi3SetIntervalDecimal");
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
{
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    NO_CLOCKS(instance, "fmi3SetIntervalFraction");
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Float64 shifts[])
{
    (void)valueReferences; (void)nValueReferences; (void)shifts;
    NO_CLOCKS(instance, "fmi3SetShiftDecimal");
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
{
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    NO_CLOCKS(instance, "fmi3SetShiftFraction");
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance)
{
    return FAIL((Instance *)instance, "fmi3EvaluateDiscreteStates: event mode is not provided");
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime)
{
    (void)discreteStatesNeedUpdate; (void)terminateSimulation; (void)nominalsOfContinuousStatesChanged;
    (void)valuesOfContinuousStatesChanged; (void)nextEventTimeDefined; (void)nextEventTime;
    return FAIL((Instance *)instance, "fmi3UpdateDiscreteStates: event mode is not provided");
}

#define NO_ME(inst, fn) return FAIL((Instance *)(inst), "%s: Model Exchange is not provided", (fn))

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) { NO_ME(instance, "fmi3EnterContinuousTimeMode"); }

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation)
{
    (void)noSetFMUStatePriorToCurrentPoint; (void)enterEventMode; (void)terminateSimulation;
    NO_ME(instance, "fmi3CompletedIntegratorStep");
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time)
{
    (void)time;
    NO_ME(instance, "fmi3SetTime");
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[], size_t nContinuousStates)
{
    (void)continuousStates; (void)nContinuousStates;
    NO_ME(instance, "fmi3SetContinuousStates");
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[], size_t nContinuousStates)
{
    (void)derivatives; (void)nContinuousStates;
    NO_ME(instance, "fmi3GetContinuousStateDerivatives");
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[], size_t nEventIndicators)
{
    (void)eventIndicators; (void)nEventIndicators;
    NO_ME(instance, "fmi3GetEventIndicators");
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[], size_t nContinuousStates)
{
    (void)continuousStates; (void)nContinuousStates;
    NO_ME(instance, "fmi3GetContinuousStates");
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t nContinuousStates)
{
    (void)nominals; (void)nContinuousStates;
    NO_ME(instance, "fmi3GetNominalsOfContinuousStates");
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators)
{
    (void)nEventIndicators;
    NO_ME(instance, "fmi3GetNumberOfEventIndicators");
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates)
{
    (void)nContinuousStates;
    NO_ME(instance, "fmi3GetNumberOfContinuousStates");
}

/* ---- Co-Simulation ------------------------------------------------------------------------ */

fmi3Status fmi3EnterStepMode(fmi3Instance instance)
{
    return FAIL((Instance *)instance, "fmi3EnterStepMode: event mode is not provided, the instance is in step mode");
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[],
                                    size_t nValues)
{
    (void)valueReferences; (void)nValueReferences; (void)orders; (void)values; (void)nValues;
    return FAIL((Instance *)instance, "fmi3GetOutputDerivatives is not provided (maxOutputDerivativeOrder=0)");
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime)
{
    char msg[256];
    int rc;
    Instance *inst = enter(instance, "fmi3DoStep", PH_STEP);
    (void)noSetFMUStatePriorToCurrentPoint;
    if (inst == NULL)
        return fmi3Error;
    if (eventHandlingNeeded == NULL || terminateSimulation == NULL || earlyReturn == NULL || lastSuccessfulTime == NULL)
        return FAIL(inst, "fmi3DoStep: NULL output argument");
    rc = core_do_step(&inst->core, currentCommunicationPoint, communicationStepSize, msg, sizeof msg);
    if (rc < 0)
        return FAIL(inst, "fmi3DoStep: %s", msg);
    *eventHandlingNeeded = fmi3False;
    *earlyReturn = fmi3False;
    *terminateSimulation = rc > 0 ? fmi3True : fmi3False;
    *lastSuccessfulTime = inst->core.time;
    if (rc > 0)
        log_msg(inst, fmi3OK, "%s", msg);
    return fmi3OK;
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime)
{
    (void)clockReference; (void)activationTime;
    return FAIL((Instance *)instance, "fmi3ActivateModelPartition: Scheduled Execution is not provided");
}
