/*
 * core.h: the part of an FMU instance that does not depend on the FMI version: the
 * Co-Simulation state machine, the model data, variable look-up, stepping and FMU states.
 * fmi2_slave.c and fmi3_slave.c wrap it in the two APIs.
 */
#ifndef TYPECOV_CORE_H
#define TYPECOV_CORE_H

#include "slave.h"

typedef enum {
    PH_INSTANTIATED = 1 << 0,
    PH_INIT         = 1 << 1,
    PH_STEP         = 1 << 2,
    PH_TERMINATED   = 1 << 3,
    PH_ERROR        = 1 << 4
} Phase;

#define PH_ANY (PH_INSTANTIATED | PH_INIT | PH_STEP | PH_TERMINATED | PH_ERROR)

typedef struct {
    Phase phase;
    double time;
    double stop_time;
    bool stop_defined;
    bool ended;          /* the model ended the experiment at `time` */
    bool dirty;          /* outputs must be recomputed before they are read */
    char *resources;     /* resources/ directory with a trailing '/', or NULL */
    unsigned char *data; /* MODEL_DATA_SIZE bytes */
} Core;

/* 0 on success; -1 when out of memory. resources may be NULL. */
int core_create(Core *c, const char *resources);
void core_destroy(Core *c);
void core_reset(Core *c);

const char *phase_name(Phase p);
const VarInfo *core_lookup(unsigned vr);
void *core_field(Core *c, const VarInfo *v);
/* NULL when v may be set now, else why not. */
const char *core_why_not_settable(const Core *c, const VarInfo *v);
/* Bring outputs up to date before a read. */
void core_refresh(Core *c);

int core_exit_initialization(Core *c, char *msg, size_t n);
/* 0: step completed; 1: the model ended the experiment (c->time is where); -1: error (msg). */
int core_do_step(Core *c, double t, double h, char *msg, size_t n);

/* FMU states: a flat copy of the core's scalars and the model data. */
size_t core_state_size(void);
void core_save(const Core *c, unsigned char *buffer);
void core_restore(Core *c, const unsigned char *buffer);

/* The directory of a file: URI ("file:///a/b", "file:/a/b") with a trailing '/'; malloc'ed. */
char *path_from_uri(const char *uri);

#endif /* TYPECOV_CORE_H */
