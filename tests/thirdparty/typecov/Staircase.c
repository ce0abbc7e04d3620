/*
 * Staircase: time events and an experiment the model ends itself.
 *
 * counter starts at 1 and grows by one at every tick (every `period` seconds from the start
 * time); when it reaches `last` the model ends the experiment at that tick (FMI 2.0: fmi2DoStep
 * returns fmi2Discard with fmi2Terminated; FMI 3.0: terminateSimulation).  Outputs:
 *
 *   counter     Integer/Int32, the stair
 *   odd         Boolean, counter is odd
 *   phase       Enumeration Phase (rising = 1, holding = 2, falling = 3): (counter - 1) mod 3 + 1
 *   since_tick  Real/Float64 [s], time since the last tick
 *   label       String, "step <counter>"
 *
 * Ticks fall exactly on start + k * period; a step is split at each tick it passes.  Changing
 * the tunable `period` moves the next tick to (last tick + new period), or to now if that has
 * passed.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "slave.h"

const char MODEL_TOKEN[] = "{0b6d1c36-7f3a-4b8e-8f55-2c1e9d4a6b70}";

typedef struct {
    double time;   /* the independent variable (declared in the FMI 3.0 description) */
    double period;
    int32_t last;
    int32_t counter;
    bool odd;
    int64_t phase;
    double since_tick;
    char label[STRING_CAPACITY];
    double t_tick;
} Data;

#define V(vr, name, type, settable) {vr, #name, type, settable, offsetof(Data, name)}

const VarInfo MODEL_VARIABLES[] = {
    V(0, time, VT_FLOAT64, SET_NEVER),
    V(1, period, VT_FLOAT64, SET_TUNABLE),
    V(2, last, VT_INT32, SET_FIXED),
    V(10, counter, VT_INT32, SET_NEVER),
    V(11, odd, VT_BOOLEAN, SET_NEVER),
    V(12, phase, VT_ENUMERATION, SET_NEVER),
    V(13, since_tick, VT_FLOAT64, SET_NEVER),
    V(14, label, VT_STRING, SET_NEVER),
};

const size_t MODEL_N_VARIABLES = sizeof MODEL_VARIABLES / sizeof MODEL_VARIABLES[0];
const size_t MODEL_DATA_SIZE = sizeof(Data);

void model_start(void *data)
{
    Data *m = data;
    m->period = 1.0;
    m->last = 10;
    m->counter = 1;
    m->t_tick = 0.0;
}

int model_initialize(void *data, double t0, const char *resources, char *msg, size_t n)
{
    Data *m = data;
    (void)resources;
    if (!(m->period > 0.0)) {
        snprintf(msg, n, "period must be > 0 s, got %g", m->period);
        return -1;
    }
    if (m->last <= m->counter) {
        snprintf(msg, n, "last must be greater than the first counter value %d, got %d", m->counter, m->last);
        return -1;
    }
    m->t_tick = t0;
    return 0;
}

void model_outputs(void *data, double t)
{
    Data *m = data;
    m->time = t;
    m->odd = (m->counter % 2) != 0;
    m->phase = (m->counter - 1) % 3 + 1;
    m->since_tick = t > m->t_tick ? t - m->t_tick : 0.0;
    snprintf(m->label, STRING_CAPACITY, "step %d", (int)m->counter);
}

int model_advance(void *data, double *t, double t_end, bool *terminate, char *msg, size_t n)
{
    Data *m = data;
    const double tol = 1e-9 * fmax(1.0, fabs(t_end));

    *terminate = false;
    if (!(m->period > 0.0)) {
        snprintf(msg, n, "period must be > 0 s, got %g", m->period);
        return -1;
    }
    for (;;) {
        double next = m->t_tick + m->period;
        if (next < *t)
            next = *t;
        if (next > t_end + tol)
            break;
        *t = next;
        m->t_tick = next;
        m->counter++;
        if (m->counter >= m->last) {
            *terminate = true;
            snprintf(msg, n, "counter reached last = %d: the experiment ends at t=%.17g s", (int)m->last, next);
            return 0;
        }
    }
    *t = t_end;
    return 0;
}
