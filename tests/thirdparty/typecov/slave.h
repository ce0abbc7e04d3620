/*
 * slave.h: what a test model provides to the FMI 2.0 and FMI 3.0 Co-Simulation wrappers
 * (fmi2_slave.c, fmi3_slave.c).
 *
 * A model keeps every variable in one plain struct (no pointers, so an FMU state is a copy of
 * it) and describes them in a table: value reference, name, type, when it may be set, and
 * where it lives in the struct.  The wrappers do the FMI state machine, type checks,
 * logging and FMU states; the model does the physics:
 *
 *   model_start       every variable to its start value (fmiInstantiate, fmiReset)
 *   model_initialize  once, when initialisation ends (reads resources, sets states)
 *   model_outputs     outputs and calculated parameters from states, inputs and parameters
 *   model_advance     from *t to t_end; may stop early and ask to end the experiment
 *
 * Value references are unique over all types, so one table serves both FMI versions.
 */
#ifndef TYPECOV_SLAVE_H
#define TYPECOV_SLAVE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define STRING_CAPACITY 128
#define BINARY_CAPACITY 64

typedef enum {
    VT_FLOAT32, VT_FLOAT64,
    VT_INT8, VT_UINT8, VT_INT16, VT_UINT16, VT_INT32, VT_UINT32, VT_INT64, VT_UINT64,
    VT_BOOLEAN, VT_STRING, VT_ENUMERATION, VT_BINARY
} ValueType;

/* Storage of each type in the model struct: float, double, int8_t ... uint64_t, bool,
 * char[STRING_CAPACITY], int64_t (enumeration), Bytes (binary). */
typedef struct {
    size_t size;
    unsigned char data[BINARY_CAPACITY];
} Bytes;

/* When a variable may be set. */
typedef enum {
    SET_NEVER,       /* constants, calculated parameters, outputs, locals */
    SET_STRUCTURAL,  /* FMI 3.0 structural parameters: only while instantiated */
    SET_FIXED,       /* fixed parameters: while instantiated or initialising */
    SET_TUNABLE      /* tunable parameters and inputs: also between steps */
} Settable;

typedef struct {
    unsigned vr;
    const char *name;
    ValueType type;
    Settable settable;
    size_t offset;   /* offsetof(the model struct, field) */
} VarInfo;

/* Provided by the model. */
extern const char MODEL_TOKEN[];            /* guid (FMI 2.0) / instantiationToken (FMI 3.0) */
extern const VarInfo MODEL_VARIABLES[];
extern const size_t MODEL_N_VARIABLES;
extern const size_t MODEL_DATA_SIZE;        /* sizeof the model struct */

void model_start(void *data);
/* resources: the FMU's resources/ directory with a trailing '/', or NULL. 0 on success, else
 * a message in msg. */
int model_initialize(void *data, double t0, const char *resources, char *msg, size_t n);
void model_outputs(void *data, double t);
/* Advance from *t to t_end (> *t). On return *t is the time reached: t_end, or earlier when
 * the model ends the experiment (*terminate set). 0 on success, else a message in msg. */
int model_advance(void *data, double *t, double t_end, bool *terminate, char *msg, size_t n);

#endif /* TYPECOV_SLAVE_H */
