/*
 * fmi2_slave.c: the FMI 2.0 Co-Simulation API over core.c and a model (slave.h).
 *
 * Types: Real = VT_FLOAT64, Integer = VT_INT32 and VT_ENUMERATION, Boolean, String.  A model
 * built for FMI 2.0 declares no other type.  When the model ends the experiment inside a
 * step, fmi2DoStep returns fmi2Discard, fmi2GetBooleanStatus(fmi2Terminated) is fmi2True and
 * fmi2GetRealStatus(fmi2LastSuccessfulTime) is the time it ended at.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "core.h"

typedef struct {
    Core core;
    char *name;
    fmi2CallbackFunctions cb;
    fmi2Boolean logging_on;
    fmi2Boolean discarded;   /* the last fmi2DoStep returned fmi2Discard */
} Instance;

/* Errors and discards are always reported; other messages only with logging on. */
static void log_msg(const Instance *inst, fmi2Status status, const char *fmt, ...)
{
    char raw[512], safe[1024];
    size_t i, j;
    va_list ap;
    const char *category = status == fmi2Error || status == fmi2Fatal ? "logStatusError"
                           : status == fmi2Discard ? "logStatusDiscard" : "logAll";

    if (inst == NULL || inst->cb.logger == NULL)
        return;
    if (status < fmi2Discard && !inst->logging_on)
        return;
    va_start(ap, fmt);
    vsnprintf(raw, sizeof raw, fmt, ap);
    va_end(ap);
    /* the logger is printf-like: double every '%' so the text passes through verbatim */
    for (i = 0, j = 0; raw[i] != '\0' && j + 2 < sizeof safe; i++) {
        safe[j++] = raw[i];
        if (raw[i] == '%')
            safe[j++] = '%';
    }
    safe[j] = '\0';
    inst->cb.logger(inst->cb.componentEnvironment, inst->name, status, category, safe);
}

#define FAIL(inst, ...) (log_msg((inst), fmi2Error, __VA_ARGS__), fmi2Error)

static Instance *enter(fmi2Component c, const char *fn, int allowed)
{
    Instance *inst = (Instance *)c;
    if (inst == NULL)
        return NULL;
    if (!((int)inst->core.phase & allowed)) {
        log_msg(inst, fmi2Error, "%s: not allowed in %s", fn, phase_name(inst->core.phase));
        return NULL;
    }
    return inst;
}

/* ---- version, logging, life cycle ------------------------------------------------------ */

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    Instance *inst = enter(c, "fmi2SetDebugLogging", PH_ANY);
    (void)nCategories;
    (void)categories;
    if (inst == NULL)
        return fmi2Error;
    inst->logging_on = loggingOn;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    Instance *inst;
    char *resources = NULL;
    (void)visible;

    if (functions == NULL || functions->logger == NULL)
        return NULL;
    if (instanceName == NULL || instanceName[0] == '\0') {
        functions->logger(functions->componentEnvironment, "?", fmi2Error, "logStatusError",
                          "fmi2Instantiate: missing instance name");
        return NULL;
    }
    if (fmuType != fmi2CoSimulation) {
        functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError",
                          "fmi2Instantiate: only Co-Simulation is supported");
        return NULL;
    }
    if (fmuGUID == NULL || strcmp(fmuGUID, MODEL_TOKEN) != 0) {
        functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError",
                          "fmi2Instantiate: wrong GUID");
        return NULL;
    }
    inst = calloc(1, sizeof *inst);
    if (inst == NULL)
        return NULL;
    inst->cb = *functions;
    inst->logging_on = loggingOn;
    inst->name = malloc(strlen(instanceName) + 1);
    if (fmuResourceLocation != NULL)
        resources = path_from_uri(fmuResourceLocation);
    if (inst->name == NULL || core_create(&inst->core, resources) != 0) {
        free(inst->name);
        free(resources);
        free(inst);
        return NULL;
    }
    free(resources);
    strcpy(inst->name, instanceName);
    return inst;
}

void fmi2FreeInstance(fmi2Component c)
{
    Instance *inst = (Instance *)c;
    if (inst == NULL)
        return;
    core_destroy(&inst->core);
    free(inst->name);
    free(inst);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    Instance *inst = enter(c, "fmi2SetupExperiment", PH_INSTANTIATED);
    (void)toleranceDefined;
    (void)tolerance;
    if (inst == NULL)
        return fmi2Error;
    if (stopTimeDefined && stopTime < startTime)
        return FAIL(inst, "fmi2SetupExperiment: stop time %g is before start time %g", stopTime, startTime);
    inst->core.time = startTime;
    inst->core.stop_defined = stopTimeDefined ? true : false;
    inst->core.stop_time = stopTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    Instance *inst = enter(c, "fmi2EnterInitializationMode", PH_INSTANTIATED);
    if (inst == NULL)
        return fmi2Error;
    inst->core.phase = PH_INIT;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    char msg[256];
    Instance *inst = enter(c, "fmi2ExitInitializationMode", PH_INIT);
    if (inst == NULL)
        return fmi2Error;
    if (core_exit_initialization(&inst->core, msg, sizeof msg) != 0)
        return FAIL(inst, "fmi2ExitInitializationMode: %s", msg);
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c)
{
    Instance *inst = enter(c, "fmi2Terminate", PH_STEP | PH_ERROR);
    if (inst == NULL)
        return fmi2Error;
    inst->core.phase = PH_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c)
{
    Instance *inst = enter(c, "fmi2Reset", PH_ANY);
    if (inst == NULL)
        return fmi2Error;
    core_reset(&inst->core);
    inst->discarded = fmi2False;
    return fmi2OK;
}

/* ---- values ---------------------------------------------------------------------------- */

/* The variable of vr if it has one of the two types (b may equal a), else NULL and an error. */
static const VarInfo *typed(Instance *inst, const char *fn, fmi2ValueReference vr, ValueType a, ValueType b)
{
    const VarInfo *v = core_lookup(vr);
    if (v == NULL) {
        log_msg(inst, fmi2Error, "%s: unknown value reference %u", fn, vr);
        return NULL;
    }
    if (v->type != a && v->type != b) {
        log_msg(inst, fmi2Error, "%s: value reference %u (%s) has another type", fn, vr, v->name);
        return NULL;
    }
    return v;
}

static const VarInfo *settable(Instance *inst, const char *fn, fmi2ValueReference vr, ValueType a, ValueType b)
{
    const char *why;
    const VarInfo *v = typed(inst, fn, vr, a, b);
    if (v == NULL)
        return NULL;
    why = core_why_not_settable(&inst->core, v);
    if (why != NULL) {
        log_msg(inst, fmi2Error, "%s: %s cannot be set in %s: %s", fn, v->name,
                phase_name(inst->core.phase), why);
        return NULL;
    }
    return v;
}

#define GETTABLE (PH_INSTANTIATED | PH_INIT | PH_STEP | PH_TERMINATED | PH_ERROR)
#define SETTABLE (PH_INSTANTIATED | PH_INIT | PH_STEP)

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    size_t i;
    Instance *inst = enter(c, "fmi2GetReal", GETTABLE);
    if (inst == NULL)
        return fmi2Error;
    core_refresh(&inst->core);
    for (i = 0; i < nvr; i++) {
        const VarInfo *v = typed(inst, "fmi2GetReal", vr[i], VT_FLOAT64, VT_FLOAT64);
        if (v == NULL)
            return fmi2Error;
        value[i] = *(const double *)core_field(&inst->core, v);
    }
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[])
{
    size_t i;
    Instance *inst = enter(c, "fmi2GetInteger", GETTABLE);
    if (inst == NULL)
        return fmi2Error;
    core_refresh(&inst->core);
    for (i = 0; i < nvr; i++) {
        const VarInfo *v = typed(inst, "fmi2GetInteger", vr[i], VT_INT32, VT_ENUMERATION);
        if (v == NULL)
            return fmi2Error;
        if (v->type == VT_INT32)
            value[i] = *(const int32_t *)core_field(&inst->core, v);
        else
            value[i] = (fmi2Integer)*(const int64_t *)core_field(&inst->core, v);
    }
    return fmi2OK;
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[])
{
    size_t i;
    Instance *inst = enter(c, "fmi2GetBoolean", GETTABLE);
    if (inst == NULL)
        return fmi2Error;
    core_refresh(&inst->core);
    for (i = 0; i < nvr; i++) {
        const VarInfo *v = typed(inst, "fmi2GetBoolean", vr[i], VT_BOOLEAN, VT_BOOLEAN);
        if (v == NULL)
            return fmi2Error;
        value[i] = *(const bool *)core_field(&inst->core, v) ? fmi2True : fmi2False;
    }
    return fmi2OK;
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[])
{
    size_t i;
    Instance *inst = enter(c, "fmi2GetString", GETTABLE);
    if (inst == NULL)
        return fmi2Error;
    core_refresh(&inst->core);
    for (i = 0; i < nvr; i++) {
        const VarInfo *v = typed(inst, "fmi2GetString", vr[i], VT_STRING, VT_STRING);
        if (v == NULL)
            return fmi2Error;
        value[i] = (const char *)core_field(&inst->core, v);
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[])
{
    size_t i;
    Instance *inst = enter(c, "fmi2SetReal", SETTABLE);
    if (inst == NULL)
        return fmi2Error;
    for (i = 0; i < nvr; i++) {
        const VarInfo *v = settable(inst, "fmi2SetReal", vr[i], VT_FLOAT64, VT_FLOAT64);
        if (v == NULL)
            return fmi2Error;
        *(double *)core_field(&inst->core, v) = value[i];
    }
    inst->core.dirty = true;
    return fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[])
{
    size_t i;
    Instance *inst = enter(c, "fmi2SetInteger", SETTABLE);
    if (inst == NULL)
        return fmi2Error;
    for (i = 0; i < nvr; i++) {
        const VarInfo *v = settable(inst, "fmi2SetInteger", vr[i], VT_INT32, VT_ENUMERATION);
        if (v == NULL)
            return fmi2Error;
        if (v->type == VT_INT32)
            *(int32_t *)core_field(&inst->core, v) = value[i];
        else
            *(int64_t *)core_field(&inst->core, v) = value[i];
    }
    inst->core.dirty = true;
    return fmi2OK;
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[])
{
    size_t i;
    Instance *inst = enter(c, "fmi2SetBoolean", SETTABLE);
    if (inst == NULL)
        return fmi2Error;
    for (i = 0; i < nvr; i++) {
        const VarInfo *v = settable(inst, "fmi2SetBoolean", vr[i], VT_BOOLEAN, VT_BOOLEAN);
        if (v == NULL)
            return fmi2Error;
        *(bool *)core_field(&inst->core, v) = value[i] != fmi2False;
    }
    inst->core.dirty = true;
    return fmi2OK;
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[])
{
    size_t i;
    Instance *inst = enter(c, "fmi2SetString", SETTABLE);
    if (inst == NULL)
        return fmi2Error;
    for (i = 0; i < nvr; i++) {
        const VarInfo *v = settable(inst, "fmi2SetString", vr[i], VT_STRING, VT_STRING);
        if (v == NULL)
            return fmi2Error;
        if (value[i] == NULL)
            return FAIL(inst, "fmi2SetString: NULL value for %s", v->name);
        if (strlen(value[i]) >= STRING_CAPACITY)
            return FAIL(inst, "fmi2SetString: %s takes at most %d characters", v->name, STRING_CAPACITY - 1);
        strcpy((char *)core_field(&inst->core, v), value[i]);
    }
    inst->core.dirty = true;
    return fmi2OK;
}

/* ---- FMU state --------------------------------------------------------------------------- */

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    unsigned char *buffer;
    Instance *inst = enter(c, "fmi2GetFMUstate", PH_ANY);
    if (inst == NULL || FMUstate == NULL)
        return fmi2Error;
    buffer = *FMUstate != NULL ? (unsigned char *)*FMUstate : malloc(core_state_size());
    if (buffer == NULL)
        return FAIL(inst, "fmi2GetFMUstate: out of memory");
    core_save(&inst->core, buffer);
    *FMUstate = buffer;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate)
{
    Instance *inst = enter(c, "fmi2SetFMUstate", PH_ANY);
    if (inst == NULL || FMUstate == NULL)
        return fmi2Error;
    core_restore(&inst->core, (const unsigned char *)FMUstate);
    inst->discarded = fmi2False;
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    Instance *inst = enter(c, "fmi2FreeFMUstate", PH_ANY);
    if (inst == NULL || FMUstate == NULL)
        return fmi2Error;
    free(*FMUstate);
    *FMUstate = NULL;
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size)
{
    Instance *inst = enter(c, "fmi2SerializedFMUstateSize", PH_ANY);
    (void)FMUstate;
    if (inst == NULL || size == NULL)
        return fmi2Error;
    *size = core_state_size();
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[], size_t size)
{
    Instance *inst = enter(c, "fmi2SerializeFMUstate", PH_ANY);
    if (inst == NULL || FMUstate == NULL)
        return fmi2Error;
    if (size != core_state_size())
        return FAIL(inst, "fmi2SerializeFMUstate: size %zu, expected %zu", size, core_state_size());
    memcpy(serializedState, FMUstate, size);
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate *FMUstate)
{
    unsigned char *buffer;
    Instance *inst = enter(c, "fmi2DeSerializeFMUstate", PH_ANY);
    if (inst == NULL || FMUstate == NULL)
        return fmi2Error;
    if (size != core_state_size())
        return FAIL(inst, "fmi2DeSerializeFMUstate: size %zu, expected %zu", size, core_state_size());
    buffer = malloc(size);
    if (buffer == NULL)
        return FAIL(inst, "fmi2DeSerializeFMUstate: out of memory");
    memcpy(buffer, serializedState, size);
    *FMUstate = buffer;
    return fmi2OK;
}

/* ---- not provided (declared false in modelDescription.xml) -------------------------------- */

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[])
{
    (void)vUnknown_ref; (void)nUnknown; (void)vKnown_ref; (void)nKnown; (void)dvKnown; (void)dvUnknown;
    return FAIL((Instance *)c, "fmi2GetDirectionalDerivative is not provided");
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    (void)vr; (void)nvr; (void)order; (void)value;
    return FAIL((Instance *)c, "fmi2SetRealInputDerivatives is not provided (canInterpolateInputs=false)");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    (void)vr; (void)nvr; (void)order; (void)value;
    return FAIL((Instance *)c, "fmi2GetRealOutputDerivatives is not provided (maxOutputDerivativeOrder=0)");
}

fmi2Status fmi2CancelStep(fmi2Component c)
{
    return FAIL((Instance *)c, "fmi2CancelStep: fmi2DoStep never returns fmi2Pending");
}

/* ---- stepping and status ----------------------------------------------------------------- */

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    char msg[256];
    int rc;
    Instance *inst = enter(c, "fmi2DoStep", PH_STEP);
    (void)noSetFMUStatePriorToCurrentPoint;
    if (inst == NULL)
        return fmi2Error;
    rc = core_do_step(&inst->core, currentCommunicationPoint, communicationStepSize, msg, sizeof msg);
    if (rc < 0)
        return FAIL(inst, "fmi2DoStep: %s", msg);
    if (rc > 0) {
        inst->discarded = fmi2True;
        log_msg(inst, fmi2Discard, "%s", msg);
        return fmi2Discard;
    }
    return fmi2OK;
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    Instance *inst = enter(c, "fmi2GetStatus", PH_ANY);
    if (inst == NULL || value == NULL)
        return fmi2Error;
    if (s == fmi2DoStepStatus) {
        *value = inst->discarded ? fmi2Discard : fmi2OK;
        return fmi2OK;
    }
    log_msg(inst, fmi2Discard, "fmi2GetStatus: status kind %d is not provided", (int)s);
    return fmi2Discard;
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    Instance *inst = enter(c, "fmi2GetRealStatus", PH_ANY);
    if (inst == NULL || value == NULL)
        return fmi2Error;
    if (s == fmi2LastSuccessfulTime) {
        *value = inst->core.time;
        return fmi2OK;
    }
    log_msg(inst, fmi2Discard, "fmi2GetRealStatus: status kind %d is not provided", (int)s);
    return fmi2Discard;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    (void)value;
    log_msg((Instance *)c, fmi2Discard, "fmi2GetIntegerStatus: status kind %d is not provided", (int)s);
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    Instance *inst = enter(c, "fmi2GetBooleanStatus", PH_ANY);
    if (inst == NULL || value == NULL)
        return fmi2Error;
    if (s == fmi2Terminated) {
        *value = inst->core.ended ? fmi2True : fmi2False;
        return fmi2OK;
    }
    log_msg(inst, fmi2Discard, "fmi2GetBooleanStatus: status kind %d is not provided", (int)s);
    return fmi2Discard;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    (void)value;
    log_msg((Instance *)c, fmi2Discard, "fmi2GetStringStatus: status kind %d is not provided", (int)s);
    return fmi2Discard;
}
