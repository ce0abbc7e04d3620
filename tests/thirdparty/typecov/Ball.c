/*
 * Ball: a bouncing ball whose units come from type definitions, with state events.
 *
 *   h' = v, v' = -g; at h = 0 the ball bounces, v -> -e v; below v_min it rests on the floor.
 *
 * Free flight is integrated exactly (a parabola) and each impact time is solved for, so the
 * result does not depend on the communication step.  h, v, g and v_min take their units from
 * the declared types Height (m), Velocity (m/s) and Acceleration (m/s2); energy has its unit
 * (J/kg) on the variable; e has none.  The independent variable `time` is declared too.
 */
#include <math.h>
#include <stdio.h>

#include "slave.h"

const char MODEL_TOKEN[] = "{9a3f2e10-4c5d-4e6f-8a7b-1c2d3e4f5a6b}";

typedef struct {
    double time;
    double h, v;
    double g, e, v_min;
    int32_t bounces;
    double energy;
    bool resting;
} Data;

#define V(vr, name, type, settable) {vr, #name, type, settable, offsetof(Data, name)}

const VarInfo MODEL_VARIABLES[] = {
    V(0, time, VT_FLOAT64, SET_NEVER),
    V(1, h, VT_FLOAT64, SET_FIXED),
    V(2, v, VT_FLOAT64, SET_FIXED),
    V(3, g, VT_FLOAT64, SET_FIXED),
    V(4, e, VT_FLOAT64, SET_TUNABLE),
    V(5, v_min, VT_FLOAT64, SET_FIXED),
    V(6, bounces, VT_INT32, SET_NEVER),
    V(7, energy, VT_FLOAT64, SET_NEVER),
    V(8, resting, VT_BOOLEAN, SET_NEVER),
};

const size_t MODEL_N_VARIABLES = sizeof MODEL_VARIABLES / sizeof MODEL_VARIABLES[0];
const size_t MODEL_DATA_SIZE = sizeof(Data);

void model_start(void *data)
{
    Data *m = data;
    m->h = 1.0;
    m->v = 0.0;
    m->g = 9.81;
    m->e = 0.7;
    m->v_min = 0.1;
    m->bounces = 0;
    m->resting = false;
}

int model_initialize(void *data, double t0, const char *resources, char *msg, size_t n)
{
    Data *m = data;
    (void)t0;
    (void)resources;
    if (!(m->g > 0.0)) {
        snprintf(msg, n, "g must be > 0 m/s2, got %g", m->g);
        return -1;
    }
    if (m->h < 0.0) {
        snprintf(msg, n, "h must be >= 0 m, got %g", m->h);
        return -1;
    }
    return 0;
}

void model_outputs(void *data, double t)
{
    Data *m = data;
    m->time = t;
    m->energy = m->g * m->h + 0.5 * m->v * m->v;
}

int model_advance(void *data, double *t, double t_end, bool *terminate, char *msg, size_t n)
{
    Data *m = data;

    *terminate = false;
    if (!(m->e >= 0.0 && m->e <= 1.0)) {
        snprintf(msg, n, "e must be in [0, 1], got %g", m->e);
        return -1;
    }
    while (*t < t_end && !m->resting) {
        const double dt = t_end - *t;
        /* first positive root of h + v tau - g tau^2 / 2 = 0 */
        const double tau = (m->v + sqrt(m->v * m->v + 2.0 * m->g * m->h)) / m->g;
        if (tau <= dt) {
            const double v_impact = m->v - m->g * tau;
            *t += tau;
            m->h = 0.0;
            m->v = -m->e * v_impact;
            m->bounces++;
            if (m->v < m->v_min) {
                m->v = 0.0;
                m->resting = true;
            }
        } else {
            m->h += m->v * dt - 0.5 * m->g * dt * dt;
            m->v -= m->g * dt;
            *t = t_end;
        }
    }
    *t = t_end;
    return 0;
}
