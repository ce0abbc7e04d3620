/*
 * VanDerPol: a small, hand-written FMI 2.0 Co-Simulation slave in plain C.
 *
 * It exists to show that twin's orchestrator runs FMUs that fmu_build/ did not produce:
 * no output buffer, no solver.* parameters, nothing but the standard FMI 2.0 CS API.
 *
 *   x0' = x1
 *   x1' = mu (1 - x0^2) x1 - x0 + u
 *
 * Value references: 0 x0 (output), 1 x1 (output), 2 mu (tunable parameter), 3 u (input).
 * Each fmi2DoStep is split into n equal substeps of at most VDP_MAX_SUBSTEP seconds and
 * integrated with the classic fourth-order Runge-Kutta method, u held constant over the step.
 *
 * Build (see tests/thirdparty/build_thirdparty.py):
 *   gcc -shared -fPIC -O2 -I<fmpy>/c-code -o VanDerPol.so VanDerPol.c -lm
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "fmi2Functions.h"

#define VDP_GUID "{c3ead9b5-efda-4218-8d03-e102ed5e9a1d}"
#define VDP_MAX_SUBSTEP 1e-3

enum { VR_X0 = 0, VR_X1 = 1, VR_MU = 2, VR_U = 3, N_VR = 4 };

/* start values, as in modelDescription.xml */
static const double START[N_VR] = {2.0, 0.0, 1.0, 0.0};

/* Phases of the FMI 2.0 Co-Simulation state machine (bit flags so a call can list where it is allowed). */
typedef enum {
    PH_INSTANTIATED = 1 << 0,
    PH_INIT         = 1 << 1,
    PH_STEP         = 1 << 2,   /* slaveInitialized / stepComplete */
    PH_TERMINATED   = 1 << 3,
    PH_ERROR        = 1 << 4
} Phase;

#define PH_ANY (PH_INSTANTIATED | PH_INIT | PH_STEP | PH_TERMINATED | PH_ERROR)

enum { LOG_ERROR = 1 << 0, LOG_WARNING = 1 << 1, LOG_CALLS = 1 << 2 };
static const char *CATEGORY_NAME[] = {"logStatusError", "logStatusWarning", "logCalls"};
#define N_CATEGORIES 3

typedef struct {
    char *name;
    fmi2CallbackFunctions cb;
    fmi2Boolean logging_on;
    int categories;             /* LOG_* bits enabled by fmi2SetDebugLogging */
    Phase phase;
    double time;
    double v[N_VR];             /* x0, x1, mu, u by value reference */
} Instance;

static const char *phase_name(Phase p)
{
    switch (p) {
    case PH_INSTANTIATED: return "instantiated";
    case PH_INIT: return "initializationMode";
    case PH_STEP: return "stepComplete";
    case PH_TERMINATED: return "terminated";
    case PH_ERROR: return "error";
    }
    return "?";
}

/* Format a message and hand it to the environment's logger. Errors are always reported;
 * warnings and call traces only when logging is on and their category is enabled. */
static void log_msg(const Instance *inst, fmi2Status status, int category, const char *fmt, ...)
{
    char raw[512], safe[1024];
    size_t i, j;
    va_list ap;

    if (inst == NULL || inst->cb.logger == NULL)
        return;
    if (status < fmi2Error && !(inst->logging_on && (inst->categories & category)))
        return;
    va_start(ap, fmt);
    vsnprintf(raw, sizeof raw, fmt, ap);
    va_end(ap);
    /* The logger is printf-like: double any '%' so the text is passed through verbatim. */
    for (i = 0, j = 0; raw[i] != '\0' && j + 2 < sizeof safe; i++) {
        safe[j++] = raw[i];
        if (raw[i] == '%')
            safe[j++] = '%';
    }
    safe[j] = '\0';
    inst->cb.logger(inst->cb.componentEnvironment, inst->name, status,
                    CATEGORY_NAME[category == LOG_CALLS ? 2 : category == LOG_WARNING ? 1 : 0], safe);
}

#define FAIL(inst, ...) (log_msg((inst), fmi2Error, LOG_ERROR, __VA_ARGS__), fmi2Error)

/* The instance if the call is allowed in its current phase, else NULL (and an error is logged). */
static Instance *enter(fmi2Component c, const char *fn, int allowed)
{
    Instance *inst = (Instance *)c;
    if (inst == NULL)
        return NULL;
    if (!((int)inst->phase & allowed)) {
        log_msg(inst, fmi2Error, LOG_ERROR, "%s: not allowed in phase %s", fn, phase_name(inst->phase));
        return NULL;
    }
    log_msg(inst, fmi2OK, LOG_CALLS, "%s", fn);
    return inst;
}

static void reset_values(Instance *inst)
{
    memcpy(inst->v, START, sizeof START);
    inst->time = 0.0;
}

/* ---------------------------------------------------------------------------------------- */
/* Model                                                                                    */

static void rhs(const double x[2], double mu, double u, double dx[2])
{
    dx[0] = x[1];
    dx[1] = mu * (1.0 - x[0] * x[0]) * x[1] - x[0] + u;
}

static void rk4(double x[2], double mu, double u, double h)
{
    double k1[2], k2[2], k3[2], k4[2], y[2];
    int i;

    rhs(x, mu, u, k1);
    for (i = 0; i < 2; i++) y[i] = x[i] + 0.5 * h * k1[i];
    rhs(y, mu, u, k2);
    for (i = 0; i < 2; i++) y[i] = x[i] + 0.5 * h * k2[i];
    rhs(y, mu, u, k3);
    for (i = 0; i < 2; i++) y[i] = x[i] + h * k3[i];
    rhs(y, mu, u, k4);
    for (i = 0; i < 2; i++) x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
}

/* ---------------------------------------------------------------------------------------- */
/* Inquire platform and version, logging                                                    */

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    Instance *inst = enter(c, "fmi2SetDebugLogging", PH_ANY);
    int mask = 0;
    size_t i;
    int k;

    if (inst == NULL)
        return fmi2Error;
    if (nCategories > 0 && categories == NULL)
        return FAIL(inst, "fmi2SetDebugLogging: categories is NULL");
    for (i = 0; i < nCategories; i++) {
        for (k = 0; k < N_CATEGORIES; k++)
            if (categories[i] != NULL && strcmp(categories[i], CATEGORY_NAME[k]) == 0)
                break;
        if (k == N_CATEGORIES)
            return FAIL(inst, "fmi2SetDebugLogging: unknown log category '%s'",
                        categories[i] ? categories[i] : "(null)");
        mask |= 1 << k;
    }
    inst->logging_on = loggingOn;
    inst->categories = nCategories == 0 ? (LOG_ERROR | LOG_WARNING | LOG_CALLS) : mask;
    return fmi2OK;
}

/* ---------------------------------------------------------------------------------------- */
/* Creation and destruction                                                                 */

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    Instance tmp, *inst;
    size_t len;

    (void)fmuResourceLocation;
    (void)visible;
    if (functions == NULL || functions->allocateMemory == NULL || functions->freeMemory == NULL)
        return NULL;
    /* a stack instance so that the checks below can already log */
    memset(&tmp, 0, sizeof tmp);
    tmp.cb = *functions;
    tmp.name = (char *)(instanceName ? instanceName : "VanDerPol");
    if (instanceName == NULL || instanceName[0] == '\0') {
        log_msg(&tmp, fmi2Error, LOG_ERROR, "fmi2Instantiate: missing instance name");
        return NULL;
    }
    if (fmuType != fmi2CoSimulation) {
        log_msg(&tmp, fmi2Error, LOG_ERROR, "fmi2Instantiate: only Co-Simulation is supported");
        return NULL;
    }
    if (fmuGUID == NULL || strcmp(fmuGUID, VDP_GUID) != 0) {
        log_msg(&tmp, fmi2Error, LOG_ERROR, "fmi2Instantiate: wrong GUID %s, expected %s",
                fmuGUID ? fmuGUID : "(null)", VDP_GUID);
        return NULL;
    }
    inst = (Instance *)functions->allocateMemory(1, sizeof(Instance));
    len = strlen(instanceName);
    if (inst == NULL || (inst->name = (char *)functions->allocateMemory(len + 1, 1)) == NULL) {
        if (inst != NULL)
            functions->freeMemory(inst);
        log_msg(&tmp, fmi2Error, LOG_ERROR, "fmi2Instantiate: out of memory");
        return NULL;
    }
    memcpy(inst->name, instanceName, len + 1);
    inst->cb = *functions;
    inst->logging_on = loggingOn;
    inst->categories = LOG_ERROR | LOG_WARNING | LOG_CALLS;
    inst->phase = PH_INSTANTIATED;
    reset_values(inst);
    return inst;
}

void fmi2FreeInstance(fmi2Component c)
{
    Instance *inst = (Instance *)c;
    fmi2CallbackFreeMemory release;

    if (inst == NULL)
        return;
    release = inst->cb.freeMemory;
    release(inst->name);
    release(inst);
}

/* ---------------------------------------------------------------------------------------- */
/* Initialization, termination, reset                                                       */

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    Instance *inst = enter(c, "fmi2SetupExperiment", PH_INSTANTIATED);

    (void)toleranceDefined;
    (void)tolerance;
    if (inst == NULL)
        return fmi2Error;
    if (!isfinite(startTime))
        return FAIL(inst, "fmi2SetupExperiment: start time is not finite");
    if (stopTimeDefined && !(stopTime >= startTime))
        return FAIL(inst, "fmi2SetupExperiment: stop time %g is before start time %g", stopTime, startTime);
    inst->time = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    Instance *inst = enter(c, "fmi2EnterInitializationMode", PH_INSTANTIATED);
    if (inst == NULL)
        return fmi2Error;
    inst->phase = PH_INIT;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    Instance *inst = enter(c, "fmi2ExitInitializationMode", PH_INIT);
    if (inst == NULL)
        return fmi2Error;
    /* x0, x1 have initial="exact": nothing to solve */
    inst->phase = PH_STEP;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c)
{
    Instance *inst = enter(c, "fmi2Terminate", PH_STEP);
    if (inst == NULL)
        return fmi2Error;
    inst->phase = PH_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c)
{
    Instance *inst = enter(c, "fmi2Reset", PH_ANY);
    if (inst == NULL)
        return fmi2Error;
    reset_values(inst);
    inst->phase = PH_INSTANTIATED;
    return fmi2OK;
}

/* ---------------------------------------------------------------------------------------- */
/* Getting and setting variable values                                                      */

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    Instance *inst = enter(c, "fmi2GetReal", PH_INIT | PH_STEP | PH_TERMINATED | PH_ERROR);
    size_t i;

    if (inst == NULL)
        return fmi2Error;
    if (nvr > 0 && (vr == NULL || value == NULL))
        return FAIL(inst, "fmi2GetReal: NULL array");
    for (i = 0; i < nvr; i++) {
        if (vr[i] >= N_VR)
            return FAIL(inst, "fmi2GetReal: unknown value reference %u", (unsigned)vr[i]);
        value[i] = inst->v[vr[i]];
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[])
{
    Instance *inst = enter(c, "fmi2SetReal", PH_INSTANTIATED | PH_INIT | PH_STEP);
    size_t i;

    if (inst == NULL)
        return fmi2Error;
    if (nvr > 0 && (vr == NULL || value == NULL))
        return FAIL(inst, "fmi2SetReal: NULL array");
    /* check everything first so that a failing call changes nothing */
    for (i = 0; i < nvr; i++) {
        if (vr[i] >= N_VR)
            return FAIL(inst, "fmi2SetReal: unknown value reference %u", (unsigned)vr[i]);
        if (vr[i] == VR_X0 || vr[i] == VR_X1)
            return FAIL(inst, "fmi2SetReal: value reference %u is an output and cannot be set", (unsigned)vr[i]);
        if (!isfinite(value[i]))
            return FAIL(inst, "fmi2SetReal: value for value reference %u is not finite", (unsigned)vr[i]);
    }
    for (i = 0; i < nvr; i++)
        inst->v[vr[i]] = value[i];
    return fmi2OK;
}

/* The model has no Integer, Boolean or String variables: every value reference is unknown. */
#define NO_VARIABLES_OF_TYPE(fn, allowed)                                                   \
    Instance *inst = enter(c, fn, allowed);                                                 \
    (void)value;                                                                            \
    if (inst == NULL)                                                                       \
        return fmi2Error;                                                                   \
    if (nvr == 0)                                                                           \
        return fmi2OK;                                                                      \
    if (vr == NULL)                                                                         \
        return FAIL(inst, fn ": NULL array");                                               \
    return FAIL(inst, fn ": unknown value reference %u (the model has no such variables)",  \
                (unsigned)vr[0]);

#define GET_PHASES (PH_INIT | PH_STEP | PH_TERMINATED | PH_ERROR)
#define SET_PHASES (PH_INSTANTIATED | PH_INIT | PH_STEP)

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[])
{
    NO_VARIABLES_OF_TYPE("fmi2GetInteger", GET_PHASES)
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[])
{
    NO_VARIABLES_OF_TYPE("fmi2GetBoolean", GET_PHASES)
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[])
{
    NO_VARIABLES_OF_TYPE("fmi2GetString", GET_PHASES)
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[])
{
    NO_VARIABLES_OF_TYPE("fmi2SetInteger", SET_PHASES)
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[])
{
    NO_VARIABLES_OF_TYPE("fmi2SetBoolean", SET_PHASES)
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[])
{
    NO_VARIABLES_OF_TYPE("fmi2SetString", SET_PHASES)
}

/* ---------------------------------------------------------------------------------------- */
/* FMU state and directional derivatives: not provided (canGetAndSetFMUstate="false",      */
/* providesDirectionalDerivative="false")                                                  */

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    (void)FMUstate;
    return FAIL((Instance *)c, "fmi2GetFMUstate: not supported (canGetAndSetFMUstate=false)");
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate)
{
    (void)FMUstate;
    return FAIL((Instance *)c, "fmi2SetFMUstate: not supported (canGetAndSetFMUstate=false)");
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    (void)FMUstate;
    return FAIL((Instance *)c, "fmi2FreeFMUstate: not supported (canGetAndSetFMUstate=false)");
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size)
{
    (void)FMUstate;
    (void)size;
    return FAIL((Instance *)c, "fmi2SerializedFMUstateSize: not supported (canSerializeFMUstate=false)");
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[], size_t size)
{
    (void)FMUstate;
    (void)serializedState;
    (void)size;
    return FAIL((Instance *)c, "fmi2SerializeFMUstate: not supported (canSerializeFMUstate=false)");
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate *FMUstate)
{
    (void)serializedState;
    (void)size;
    (void)FMUstate;
    return FAIL((Instance *)c, "fmi2DeSerializeFMUstate: not supported (canSerializeFMUstate=false)");
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[])
{
    (void)vUnknown_ref;
    (void)nUnknown;
    (void)vKnown_ref;
    (void)nKnown;
    (void)dvKnown;
    (void)dvUnknown;
    return FAIL((Instance *)c, "fmi2GetDirectionalDerivative: not supported (providesDirectionalDerivative=false)");
}

/* ---------------------------------------------------------------------------------------- */
/* Co-Simulation                                                                            */

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    return FAIL((Instance *)c, "fmi2SetRealInputDerivatives: not supported (canInterpolateInputs=false)");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    return FAIL((Instance *)c, "fmi2GetRealOutputDerivatives: not supported (maxOutputDerivativeOrder=0)");
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    Instance *inst = enter(c, "fmi2DoStep", PH_STEP);
    double x[2], h;
    long n, i;

    (void)noSetFMUStatePriorToCurrentPoint;
    if (inst == NULL)
        return fmi2Error;
    if (!(communicationStepSize > 0.0) || !isfinite(communicationStepSize))
        return FAIL(inst, "fmi2DoStep: communication step size must be > 0, got %g", communicationStepSize);
    if (fabs(currentCommunicationPoint - inst->time) > 1e-9 * fmax(1.0, fabs(inst->time)))
        return FAIL(inst, "fmi2DoStep: communication point %.17g does not match the FMU time %.17g",
                    currentCommunicationPoint, inst->time);
    n = (long)ceil(communicationStepSize / VDP_MAX_SUBSTEP - 1e-9);
    if (n < 1)
        n = 1;
    h = communicationStepSize / (double)n;
    x[0] = inst->v[VR_X0];
    x[1] = inst->v[VR_X1];
    for (i = 0; i < n; i++)
        rk4(x, inst->v[VR_MU], inst->v[VR_U], h);
    if (!isfinite(x[0]) || !isfinite(x[1])) {
        inst->phase = PH_ERROR;
        return FAIL(inst, "fmi2DoStep: the state is no longer finite at t=%g", currentCommunicationPoint);
    }
    inst->v[VR_X0] = x[0];
    inst->v[VR_X1] = x[1];
    /* take the master's time, so that rounding does not accumulate over many steps */
    inst->time = currentCommunicationPoint + communicationStepSize;
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c)
{
    return FAIL((Instance *)c, "fmi2CancelStep: fmi2DoStep never returns fmi2Pending here");
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    (void)s;
    (void)value;
    return FAIL((Instance *)c, "fmi2GetStatus: no asynchronous step is pending");
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    Instance *inst = enter(c, "fmi2GetRealStatus", PH_STEP | PH_TERMINATED | PH_ERROR);
    if (inst == NULL)
        return fmi2Error;
    if (s != fmi2LastSuccessfulTime || value == NULL)
        return FAIL(inst, "fmi2GetRealStatus: only fmi2LastSuccessfulTime is available");
    *value = inst->time;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    (void)s;
    (void)value;
    return FAIL((Instance *)c, "fmi2GetIntegerStatus: no integer status is defined");
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    Instance *inst = enter(c, "fmi2GetBooleanStatus", PH_STEP | PH_TERMINATED | PH_ERROR);
    if (inst == NULL)
        return fmi2Error;
    if (s != fmi2Terminated || value == NULL)
        return FAIL(inst, "fmi2GetBooleanStatus: only fmi2Terminated is available");
    *value = fmi2False;   /* the model never asks to stop the simulation */
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    (void)s;
    (void)value;
    return FAIL((Instance *)c, "fmi2GetStringStatus: no string status is defined");
}
