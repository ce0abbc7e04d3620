/*
 * Faulty: a damped oscillator as an FMI 2.0 Co-Simulation slave that fails on request, the way
 * native FMUs fail in the field.  It exists to test that twin survives and reports such FMUs.
 *
 *   x' = v,   v' = -k x - c v + u
 *
 * Value references: 0 x (output), 1 v (output), 2 k, 3 c, 4 fault, 5 fault_time (parameters), 6 u (input).
 * From the first fmi2DoStep that ends after fault_time, the behaviour is chosen by fault:
 *   0 none, 1 segmentation fault, 2 exit(3), 3 endless loop, 4 abort(), 5 fmi2Error with a message,
 *   6 fmi2Fatal.
 * fault 7 segfaults when the last digit of round(1000 k) is 0 and loops when it is 1 (so that
 * one parameter set in ten crashes and one in ten hangs, whatever the order of the runs).
 *
 * Build: gcc -shared -fPIC -O1 -I<fmpy>/c-code -o Faulty.so Faulty.c -lm
 */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#define GUID "{5f1b7e2a-2c1d-4f57-9f3e-7d8a0c6b4e11}"
enum { VR_X, VR_V, VR_K, VR_C, VR_FAULT, VR_FAULT_TIME, VR_U, N_VR };
static const double START[N_VR] = {0.01, 0.0, 1.0e4, 2.0, 0.0, 0.0, 0.0};

typedef struct {
    fmi2CallbackFunctions cb;
    char name[64];
    double v[N_VR];
    double time;
    int initialized;
} Inst;

static void say(Inst *s, fmi2Status st, const char *msg)
{
    if (s && s->cb.logger)
        s->cb.logger(s->cb.componentEnvironment, s->name, st, "logStatusError", msg);
}

static volatile int *nowhere = NULL;

static void fail_now(Inst *s)
{
    int mode = (int)s->v[VR_FAULT];
    if (mode == 7) {
        long d = lround(1000.0 * s->v[VR_K]) % 10;
        mode = d == 0 ? 1 : d == 1 ? 3 : 0;
    }
    switch (mode) {
    case 1: *nowhere = 1; break;                /* SIGSEGV */
    case 2: exit(3);
    case 3: for (;;) { s->time += 0.0; }        /* never returns */
    case 4: abort();
    default: break;
    }
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }
fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[])
{ (void)c; (void)on; (void)n; (void)cat; return fmi2OK; }

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String res,
                              const fmi2CallbackFunctions *f, fmi2Boolean visible, fmi2Boolean logging)
{
    Inst *s;
    (void)res; (void)visible; (void)logging;
    if (f == NULL || type != fmi2CoSimulation)
        return NULL;
    if (guid == NULL || strcmp(guid, GUID) != 0) {
        Inst tmp;
        memset(&tmp, 0, sizeof tmp);
        tmp.cb = *f;
        snprintf(tmp.name, sizeof tmp.name, "%s", name ? name : "Faulty");
        say(&tmp, fmi2Error, "fmi2Instantiate: GUID does not match this binary");
        return NULL;
    }
    s = (Inst *)calloc(1, sizeof(Inst));
    if (s == NULL)
        return NULL;
    s->cb = *f;
    snprintf(s->name, sizeof s->name, "%s", name ? name : "Faulty");
    memcpy(s->v, START, sizeof START);
    return s;
}

void fmi2FreeInstance(fmi2Component c) { free(c); }

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean td, fmi2Real tol, fmi2Real t0, fmi2Boolean sd, fmi2Real t1)
{
    Inst *s = (Inst *)c;
    (void)td; (void)tol; (void)sd; (void)t1;
    s->time = t0;
    return fmi2OK;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) { ((Inst *)c)->initialized = 1; return fmi2OK; }
fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2Reset(fmi2Component c)
{
    Inst *s = (Inst *)c;
    memcpy(s->v, START, sizeof START);
    s->time = 0.0;
    s->initialized = 0;
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[])
{
    Inst *s = (Inst *)c;
    size_t i;
    for (i = 0; i < n; i++) {
        if (vr[i] >= N_VR)
            return fmi2Error;
        value[i] = s->v[vr[i]];
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[])
{
    Inst *s = (Inst *)c;
    size_t i;
    for (i = 0; i < n; i++) {
        if (vr[i] >= N_VR || vr[i] <= VR_V)
            return fmi2Error;
        s->v[vr[i]] = value[i];
    }
    return fmi2OK;
}

#define NONE_OF_TYPE(T) { (void)c; (void)vr; (void)value; return n == 0 ? fmi2OK : fmi2Error; }
fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) NONE_OF_TYPE(int)
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[]) NONE_OF_TYPE(int)
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String value[]) NONE_OF_TYPE(int)
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer value[]) NONE_OF_TYPE(int)
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean value[]) NONE_OF_TYPE(int)
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String value[]) NONE_OF_TYPE(int)

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *st) { (void)c; (void)st; return fmi2Error; }
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate st) { (void)c; (void)st; return fmi2Error; }
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *st) { (void)c; (void)st; return fmi2Error; }
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate st, size_t *n) { (void)c; (void)st; (void)n; return fmi2Error; }
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate st, fmi2Byte b[], size_t n) { (void)c; (void)st; (void)b; (void)n; return fmi2Error; }
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *st) { (void)c; (void)b; (void)n; (void)st; return fmi2Error; }
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference a[], size_t na, const fmi2ValueReference b[],
                                        size_t nb, const fmi2Real x[], fmi2Real y[])
{ (void)c; (void)a; (void)na; (void)b; (void)nb; (void)x; (void)y; return fmi2Error; }
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer o[], const fmi2Real v[])
{ (void)c; (void)vr; (void)n; (void)o; (void)v; return fmi2Error; }
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer o[], fmi2Real v[])
{ (void)c; (void)vr; (void)n; (void)o; (void)v; return fmi2Error; }

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSet)
{
    Inst *s = (Inst *)c;
    int i, n = (int)ceil(h / 1e-4);
    double dt, x = s->v[VR_X], v = s->v[VR_V];
    (void)noSet;
    if (n < 1)
        n = 1;
    dt = h / n;
    if (t + h > s->v[VR_FAULT_TIME]) {
        int mode = (int)s->v[VR_FAULT];
        if (mode == 5) {
            say(s, fmi2Error, "fmi2DoStep: the model failed on purpose");
            return fmi2Error;
        }
        if (mode == 6) {
            say(s, fmi2Fatal, "fmi2DoStep: fatal failure on purpose");
            return fmi2Fatal;
        }
        fail_now(s);
    }
    for (i = 0; i < n; i++) {   /* semi-implicit Euler */
        v += dt * (-s->v[VR_K] * x - s->v[VR_C] * v + s->v[VR_U]);
        x += dt * v;
    }
    s->v[VR_X] = x;
    s->v[VR_V] = v;
    s->time = t + h;
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c) { (void)c; return fmi2Error; }
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind k, fmi2Status *v) { (void)c; (void)k; (void)v; return fmi2Error; }
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind k, fmi2Real *v)
{ (void)k; *v = ((Inst *)c)->time; return fmi2OK; }
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind k, fmi2Integer *v) { (void)c; (void)k; (void)v; return fmi2Error; }
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind k, fmi2Boolean *v) { (void)c; (void)k; *v = fmi2False; return fmi2OK; }
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind k, fmi2String *v) { (void)c; (void)k; (void)v; return fmi2Error; }
