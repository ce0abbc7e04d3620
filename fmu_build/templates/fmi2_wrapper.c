/* Generic FMI 2.0 wrapper (Co-Simulation and Model Exchange) around the simulation core of
 * model_core.h. Nothing in this file is specific to one model: sizes, names of the generated
 * functions, defaults and bounds come from model_info.h.
 */
#include "fmi2Functions.h"
#include "model_core.h"

/* The host's callbacks, kept per instance: the logger is variadic (printf-style). */
static void host_log2(Comp *c, int status, const char *category, const char *message) {
    const fmi2CallbackFunctions *cb = (const fmi2CallbackFunctions *)c->host;
    if (cb && cb->logger) cb->logger(cb->componentEnvironment, c->name, (fmi2Status)status, category, "%s", message);
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String guid,
                              fmi2String resourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    Comp *c;
    fmi2CallbackFunctions *cb;
    (void)resourceLocation; (void)visible;
    if (!functions || !functions->logger) return NULL;
    if (!guid || strcmp(guid, MODEL_GUID) != 0) {
        functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError",
                          "GUID %s does not match this binary (%s)", guid ? guid : "(null)", MODEL_GUID);
        return NULL;
    }
    cb = (fmi2CallbackFunctions *)malloc(sizeof *cb);
    if (!cb) return NULL;
    *cb = *functions;
    c = core_new(instanceName, fmuType == fmi2ModelExchange, host_log2, cb, loggingOn);
    if (!c) { free(cb); return NULL; }
    return c;
}

void fmi2FreeInstance(fmi2Component comp) {
    Comp *c = (Comp *)comp;
    if (!c) return;
    free(c->host);
    core_free(c);
}

fmi2Status fmi2SetDebugLogging(fmi2Component comp, fmi2Boolean on, size_t n, const fmi2String cats[]) {
    (void)n; (void)cats;
    ((Comp *)comp)->logging = on;
    return fmi2OK;
}

fmi2Status fmi2SetupExperiment(fmi2Component comp, fmi2Boolean tolDefined, fmi2Real tol,
                               fmi2Real startTime, fmi2Boolean stopDefined, fmi2Real stopTime) {
    (void)tolDefined; (void)tol; (void)stopDefined; (void)stopTime;
    core_setup((Comp *)comp, startTime);
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component comp) {
    ((Comp *)comp)->phase = INITIALIZATION;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component comp) {
    core_exit_initialization((Comp *)comp);
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component comp) { ((Comp *)comp)->phase = TERMINATED; return fmi2OK; }

fmi2Status fmi2Reset(fmi2Component comp) {
    set_defaults((Comp *)comp);
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    size_t i;
    for (i = 0; i < nvr; i++)
        if (core_get_real((Comp *)comp, vr[i], &value[i], "fmi2GetReal") != ST_OK) return fmi2Error;
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    size_t i;
    for (i = 0; i < nvr; i++)
        if (core_set_real((Comp *)comp, vr[i], value[i], "fmi2SetReal") != ST_OK) return fmi2Error;
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
    size_t i;
    for (i = 0; i < nvr; i++) {
        if (vr[i] >= (fmi2ValueReference)N_C_) { logmsg((Comp *)comp, ST_ERROR, "logStatusError", "fmi2GetInteger: unknown reference %u", vr[i]); return fmi2Error; }
        value[i] = C_VALUES[vr[i]];
    }
    return fmi2OK;
}
fmi2Status fmi2SetInteger(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[]) {
    (void)vr; (void)value;
    if (nvr == 0) return fmi2OK;
    logmsg((Comp *)comp, ST_ERROR, "logStatusError", "Integer variables of this FMU are structural constants; rebuild the FMU to change them");
    return fmi2Error;
}
fmi2Status fmi2GetBoolean(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
    (void)vr; (void)value;
    if (nvr == 0) return fmi2OK;
    logmsg((Comp *)comp, ST_ERROR, "logStatusError", "this FMU has no Boolean variables");
    return fmi2Error;
}
fmi2Status fmi2SetBoolean(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[]) {
    return fmi2GetBoolean(comp, vr, nvr, (fmi2Boolean *)value);
}
fmi2Status fmi2GetString(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
    (void)vr; (void)value;
    if (nvr == 0) return fmi2OK;
    logmsg((Comp *)comp, ST_ERROR, "logStatusError", "this FMU has no String variables");
    return fmi2Error;
}
fmi2Status fmi2SetString(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
    return fmi2GetString(comp, vr, nvr, (fmi2String *)value);
}

/* ---- FMU state ------------------------------------------------------------------------- */
fmi2Status fmi2GetFMUstate(fmi2Component comp, fmi2FMUstate *state) {
    Snapshot *s = *state ? (Snapshot *)*state : (Snapshot *)calloc(1, sizeof(Snapshot));
    if (!s) return fmi2Error;
    core_snapshot((Comp *)comp, s);
    *state = s;
    return fmi2OK;
}
fmi2Status fmi2SetFMUstate(fmi2Component comp, fmi2FMUstate state) {
    if (!state) return fmi2Error;
    core_restore((Comp *)comp, (const Snapshot *)state);
    return fmi2OK;
}
fmi2Status fmi2FreeFMUstate(fmi2Component comp, fmi2FMUstate *state) {
    (void)comp;
    if (state && *state) { free(*state); *state = NULL; }
    return fmi2OK;
}
fmi2Status fmi2SerializedFMUstateSize(fmi2Component comp, fmi2FMUstate state, size_t *size) {
    (void)comp; (void)state;
    *size = core_serialized_size();
    return fmi2OK;
}
fmi2Status fmi2SerializeFMUstate(fmi2Component comp, fmi2FMUstate state, fmi2Byte bytes[], size_t size) {
    (void)comp;
    return core_serialize((const Snapshot *)state, (unsigned char *)bytes, size) == 0 ? fmi2OK : fmi2Error;
}
fmi2Status fmi2DeSerializeFMUstate(fmi2Component comp, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state) {
    Snapshot tmp, *s;
    if (core_deserialize((Comp *)comp, (const unsigned char *)bytes, size, &tmp) != 0) return fmi2Error;
    /* FMI 2.0: a non-NULL *state is an existing snapshot to overwrite, not to leak */
    s = *state ? (Snapshot *)*state : (Snapshot *)malloc(sizeof(Snapshot));
    if (!s) return fmi2Error;
    *s = tmp;
    *state = s;
    return fmi2OK;
}
fmi2Status fmi2GetDirectionalDerivative(fmi2Component comp, const fmi2ValueReference vu[], size_t nu,
                                        const fmi2ValueReference vk[], size_t nk, const fmi2Real dvk[], fmi2Real dvu[]) {
    (void)vu; (void)nu; (void)vk; (void)nk; (void)dvk; (void)dvu;
    logmsg((Comp *)comp, ST_ERROR, "logStatusError", "directional derivatives are not provided");
    return fmi2Error;
}

/* ---- Co-Simulation ----------------------------------------------------------------------- */
fmi2Status fmi2SetRealInputDerivatives(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr; (void)order; (void)value;
    if (nvr == 0) return fmi2OK;
    logmsg((Comp *)comp, ST_ERROR, "logStatusError", "input derivatives are not supported (inputs are held constant over a step)");
    return fmi2Error;
}
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr; (void)order; (void)value;
    if (nvr == 0) return fmi2OK;
    logmsg((Comp *)comp, ST_ERROR, "logStatusError", "output derivatives are not supported");
    return fmi2Error;
}

fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior) {
    (void)noSetPrior;
    return core_do_step((Comp *)comp, t, h, "fmi2DoStep") == ST_OK ? fmi2OK : fmi2Error;
}

fmi2Status fmi2CancelStep(fmi2Component comp) { (void)comp; return fmi2Error; }
fmi2Status fmi2GetStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Status *value) { (void)comp; (void)s; *value = fmi2OK; return fmi2OK; }
fmi2Status fmi2GetRealStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Real *value) {
    (void)s; *value = ((Comp *)comp)->t; return fmi2OK;
}
fmi2Status fmi2GetIntegerStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Integer *value) { (void)comp; (void)s; (void)value; return fmi2Discard; }
fmi2Status fmi2GetBooleanStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Boolean *value) { (void)comp; (void)s; *value = fmi2False; return fmi2OK; }
fmi2Status fmi2GetStringStatus(fmi2Component comp, const fmi2StatusKind s, fmi2String *value) { (void)comp; (void)s; (void)value; return fmi2Discard; }

/* ---- Model Exchange ---------------------------------------------------------------------- */
fmi2Status fmi2EnterEventMode(fmi2Component comp) { (void)comp; return fmi2OK; }
fmi2Status fmi2NewDiscreteStates(fmi2Component comp, fmi2EventInfo *info) {
    (void)comp;
    info->newDiscreteStatesNeeded = fmi2False; info->terminateSimulation = fmi2False;
    info->nominalsOfContinuousStatesChanged = fmi2False; info->valuesOfContinuousStatesChanged = fmi2False;
    info->nextEventTimeDefined = fmi2False; info->nextEventTime = 0.0;
    return fmi2OK;
}
fmi2Status fmi2EnterContinuousTimeMode(fmi2Component comp) { (void)comp; return fmi2OK; }
fmi2Status fmi2CompletedIntegratorStep(fmi2Component comp, fmi2Boolean noSetPrior, fmi2Boolean *enterEventMode, fmi2Boolean *terminate) {
    (void)comp; (void)noSetPrior; *enterEventMode = fmi2False; *terminate = fmi2False; return fmi2OK;
}
fmi2Status fmi2SetTime(fmi2Component comp, fmi2Real time) {
    Comp *c = (Comp *)comp; c->t = time; c->y_dirty = c->xdot_dirty = 1; c->k1_valid = 0; return fmi2OK;
}
fmi2Status fmi2SetContinuousStates(fmi2Component comp, const fmi2Real x[], size_t nx) {
    return core_set_states((Comp *)comp, x, nx) == ST_OK ? fmi2OK : fmi2Error;
}
fmi2Status fmi2GetDerivatives(fmi2Component comp, fmi2Real dx[], size_t nx) {
    return core_get_derivatives((Comp *)comp, dx, nx) == ST_OK ? fmi2OK : fmi2Error;
}
fmi2Status fmi2GetEventIndicators(fmi2Component comp, fmi2Real ind[], size_t ni) { (void)comp; (void)ind; return ni == 0 ? fmi2OK : fmi2Error; }
fmi2Status fmi2GetContinuousStates(fmi2Component comp, fmi2Real x[], size_t nx) {
    return core_get_states((Comp *)comp, x, nx) == ST_OK ? fmi2OK : fmi2Error;
}
fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component comp, fmi2Real x_nominal[], size_t nx) {
    return core_get_nominals((Comp *)comp, x_nominal, nx) == ST_OK ? fmi2OK : fmi2Error;
}

/* ---- Output buffer extension (not part of FMI 2.0) ------------------------------------- */
FMI2_Export size_t twin_fmi2OutputBufferWidth(void) { return (size_t)N_Y; }

/* Copies up to `capacity` samples of the last doStep (N_Y doubles each, in output value
 * reference order) into dst and returns how many samples the buffer held. */
FMI2_Export size_t twin_fmi2GetOutputBuffer(fmi2Component comp, double *dst, size_t capacity) {
    return core_output_buffer((const Comp *)comp, dst, capacity);
}
