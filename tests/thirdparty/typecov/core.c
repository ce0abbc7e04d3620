/* core.c: see core.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core.h"

typedef struct {
    Phase phase;
    double time;
    bool ended;
} StateHeader;

static char *copy_string(const char *s)
{
    char *out;
    if (s == NULL)
        return NULL;
    out = malloc(strlen(s) + 1);
    if (out != NULL)
        strcpy(out, s);
    return out;
}

int core_create(Core *c, const char *resources)
{
    memset(c, 0, sizeof *c);
    c->data = calloc(1, MODEL_DATA_SIZE);
    if (c->data == NULL)
        return -1;
    if (resources != NULL) {
        c->resources = copy_string(resources);
        if (c->resources == NULL) {
            free(c->data);
            c->data = NULL;
            return -1;
        }
    }
    core_reset(c);
    return 0;
}

void core_destroy(Core *c)
{
    free(c->data);
    free(c->resources);
    c->data = NULL;
    c->resources = NULL;
}

void core_reset(Core *c)
{
    memset(c->data, 0, MODEL_DATA_SIZE);
    model_start(c->data);
    c->phase = PH_INSTANTIATED;
    c->time = 0.0;
    c->stop_time = 0.0;
    c->stop_defined = false;
    c->ended = false;
    c->dirty = true;
}

const char *phase_name(Phase p)
{
    switch (p) {
    case PH_INSTANTIATED: return "instantiated";
    case PH_INIT: return "initialization mode";
    case PH_STEP: return "step mode";
    case PH_TERMINATED: return "terminated";
    case PH_ERROR: return "error";
    }
    return "?";
}

const VarInfo *core_lookup(unsigned vr)
{
    size_t i;
    for (i = 0; i < MODEL_N_VARIABLES; i++)
        if (MODEL_VARIABLES[i].vr == vr)
            return &MODEL_VARIABLES[i];
    return NULL;
}

void *core_field(Core *c, const VarInfo *v)
{
    return c->data + v->offset;
}

const char *core_why_not_settable(const Core *c, const VarInfo *v)
{
    switch (v->settable) {
    case SET_NEVER:
        return "it is not a parameter or input";
    case SET_STRUCTURAL:
        return c->phase == PH_INSTANTIATED ? NULL : "a structural parameter can only be set before initialization";
    case SET_FIXED:
        return (c->phase & (PH_INSTANTIATED | PH_INIT)) ? NULL
               : "a fixed parameter can only be set before initialization ends";
    case SET_TUNABLE:
        return (c->phase & (PH_INSTANTIATED | PH_INIT | PH_STEP)) ? NULL : "the instance is not running";
    }
    return "unknown variable kind";
}

void core_refresh(Core *c)
{
    if (c->dirty) {
        model_outputs(c->data, c->time);
        c->dirty = false;
    }
}

int core_exit_initialization(Core *c, char *msg, size_t n)
{
    if (model_initialize(c->data, c->time, c->resources, msg, n) != 0) {
        c->phase = PH_ERROR;
        return -1;
    }
    c->phase = PH_STEP;
    c->dirty = true;
    return 0;
}

static int close_to(double a, double b)
{
    return fabs(a - b) <= 1e-9 * fmax(1.0, fmax(fabs(a), fabs(b)));
}

int core_do_step(Core *c, double t, double h, char *msg, size_t n)
{
    double reached, t_end;
    bool terminate = false;

    if (n > 0)
        msg[0] = '\0';
    if (c->ended) {
        snprintf(msg, n, "the model ended the experiment at t=%.17g; no step can follow", c->time);
        return -1;
    }
    if (!close_to(t, c->time)) {
        snprintf(msg, n, "expected currentCommunicationPoint = %.17g, got %.17g", c->time, t);
        return -1;
    }
    if (!(h > 0.0)) {
        snprintf(msg, n, "communication step size must be > 0, got %.17g", h);
        return -1;
    }
    t_end = t + h;
    if (c->stop_defined && t_end > c->stop_time && !close_to(t_end, c->stop_time)) {
        snprintf(msg, n, "a step to t=%.17g passes the stop time %.17g", t_end, c->stop_time);
        return -1;
    }
    reached = c->time;
    if (model_advance(c->data, &reached, t_end, &terminate, msg, n) != 0) {
        c->phase = PH_ERROR;
        return -1;
    }
    c->dirty = true;
    if (terminate) {
        c->time = reached;
        c->ended = true;
        if (n > 0 && msg[0] == '\0')
            snprintf(msg, n, "the model ended the experiment at t=%.17g", reached);
        return 1;
    }
    c->time = t_end;
    return 0;
}

size_t core_state_size(void)
{
    return sizeof(StateHeader) + MODEL_DATA_SIZE;
}

void core_save(const Core *c, unsigned char *buffer)
{
    StateHeader h;
    memset(&h, 0, sizeof h);
    h.phase = c->phase;
    h.time = c->time;
    h.ended = c->ended;
    memcpy(buffer, &h, sizeof h);
    memcpy(buffer + sizeof h, c->data, MODEL_DATA_SIZE);
}

void core_restore(Core *c, const unsigned char *buffer)
{
    StateHeader h;
    memcpy(&h, buffer, sizeof h);
    c->phase = h.phase;
    c->time = h.time;
    c->ended = h.ended;
    memcpy(c->data, buffer + sizeof h, MODEL_DATA_SIZE);
    c->dirty = true;
}

char *path_from_uri(const char *uri)
{
    const char *p = uri;
    size_t len;
    char *out;

    if (uri == NULL)
        return NULL;
    if (strncmp(p, "file://", 7) == 0) {
        p += 7;                       /* file:///a/b -> /a/b; file://host/a is not supported */
        if (*p != '/')
            return NULL;
    } else if (strncmp(p, "file:", 5) == 0) {
        p += 5;                       /* file:/a/b */
    }
    len = strlen(p);
    out = malloc(len + 2);
    if (out == NULL)
        return NULL;
    /* undo percent-encoding (spaces and other reserved characters in the path) */
    {
        size_t i, j = 0;
        for (i = 0; i < len; i++) {
            unsigned hex;
            if (p[i] == '%' && i + 2 < len && sscanf(p + i + 1, "%2x", &hex) == 1) {
                out[j++] = (char)hex;
                i += 2;
            } else {
                out[j++] = p[i];
            }
        }
        if (j == 0 || out[j - 1] != '/')
            out[j++] = '/';
        out[j] = '\0';
    }
    return out;
}
