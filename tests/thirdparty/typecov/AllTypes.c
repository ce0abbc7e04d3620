/*
 * AllTypes: inputs, outputs and parameters of every FMI variable type.
 *
 * FMI 2.0 and FMI 3.0 builds share the types Real/Float64, Integer/Int32, Boolean, String and
 * Enumeration (declaredType Mode: off = 1, slow = 2, fast = 3):
 *
 *   Real_output        = gain * Real_input + offset
 *   Real_integral      = integral of gain * Real_input dt from the start time (a state)
 *   Integer_output     = Integer_input + step * (whole seconds since the start time)
 *   Boolean_output     = Boolean_input xor invert
 *   String_output      = label ":" String_input
 *   Enumeration_output = Enumeration_input if Boolean_input, else mode
 *   resource_text      = first line of resources/message.txt, resource_length its length
 *   teeth              = 19 (a constant), ratio = 2 offset (a calculated parameter)
 *
 * The FMI 3.0 build adds, for T in Int8, UInt8, Int16, UInt16, UInt32, Int64, UInt64,
 * T_output = T_input xor T_parameter (exact in every type), Float32_output =
 * Float32_input * (float)gain, Binary_output = the bytes of String_output, and a structural
 * parameter `sections`.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "slave.h"

#ifndef FMI_VERSION
#error "compile with -DFMI_VERSION=2 or -DFMI_VERSION=3"
#endif

const char MODEL_TOKEN[] = "{5e0c7a1e-1b7c-4c55-9a63-7d8f0c2b9a11}";

typedef struct {
    double time;   /* the independent variable (declared in the FMI 3.0 description) */
    double gain, offset, ratio;
    int32_t step, teeth;
    bool invert;
    char label[STRING_CAPACITY];
    int64_t mode;

    double Real_input;
    int32_t Integer_input;
    bool Boolean_input;
    char String_input[STRING_CAPACITY];
    int64_t Enumeration_input;

    double Real_output, Real_integral;
    int32_t Integer_output;
    bool Boolean_output;
    char String_output[2 * STRING_CAPACITY];  /* label:String_input, never truncated */
    int64_t Enumeration_output;
    char resource_text[STRING_CAPACITY];
    int32_t resource_length;

    float Float32_input, Float32_output;
    int8_t Int8_input, Int8_parameter, Int8_output;
    uint8_t UInt8_input, UInt8_parameter, UInt8_output;
    int16_t Int16_input, Int16_parameter, Int16_output;
    uint16_t UInt16_input, UInt16_parameter, UInt16_output;
    uint32_t UInt32_input, UInt32_parameter, UInt32_output;
    int64_t Int64_input, Int64_parameter, Int64_output;
    uint64_t UInt64_input, UInt64_parameter, UInt64_output;
    Bytes Binary_output;
    uint16_t sections;

    double t0;
} Data;

#define V(vr, name, type, settable) {vr, #name, type, settable, offsetof(Data, name)}

const VarInfo MODEL_VARIABLES[] = {
    V(0, time, VT_FLOAT64, SET_NEVER),
    V(1, gain, VT_FLOAT64, SET_TUNABLE),
    V(2, offset, VT_FLOAT64, SET_FIXED),
    V(3, step, VT_INT32, SET_TUNABLE),
    V(4, invert, VT_BOOLEAN, SET_TUNABLE),
    V(5, label, VT_STRING, SET_FIXED),
    V(6, mode, VT_ENUMERATION, SET_TUNABLE),
    V(7, teeth, VT_INT32, SET_NEVER),
    V(8, ratio, VT_FLOAT64, SET_NEVER),
    V(10, Real_input, VT_FLOAT64, SET_TUNABLE),
    V(11, Integer_input, VT_INT32, SET_TUNABLE),
    V(12, Boolean_input, VT_BOOLEAN, SET_TUNABLE),
    V(13, String_input, VT_STRING, SET_TUNABLE),
    V(14, Enumeration_input, VT_ENUMERATION, SET_TUNABLE),
    V(20, Real_output, VT_FLOAT64, SET_NEVER),
    V(21, Real_integral, VT_FLOAT64, SET_NEVER),
    V(22, Integer_output, VT_INT32, SET_NEVER),
    V(23, Boolean_output, VT_BOOLEAN, SET_NEVER),
    V(24, String_output, VT_STRING, SET_NEVER),
    V(25, Enumeration_output, VT_ENUMERATION, SET_NEVER),
    V(26, resource_text, VT_STRING, SET_NEVER),
    V(27, resource_length, VT_INT32, SET_NEVER),
#if FMI_VERSION == 3
    V(30, Float32_input, VT_FLOAT32, SET_TUNABLE),
    V(31, Float32_output, VT_FLOAT32, SET_NEVER),
    V(32, Int8_input, VT_INT8, SET_TUNABLE),
    V(33, Int8_parameter, VT_INT8, SET_TUNABLE),
    V(34, Int8_output, VT_INT8, SET_NEVER),
    V(35, UInt8_input, VT_UINT8, SET_TUNABLE),
    V(36, UInt8_parameter, VT_UINT8, SET_TUNABLE),
    V(37, UInt8_output, VT_UINT8, SET_NEVER),
    V(38, Int16_input, VT_INT16, SET_TUNABLE),
    V(39, Int16_parameter, VT_INT16, SET_TUNABLE),
    V(40, Int16_output, VT_INT16, SET_NEVER),
    V(41, UInt16_input, VT_UINT16, SET_TUNABLE),
    V(42, UInt16_parameter, VT_UINT16, SET_TUNABLE),
    V(43, UInt16_output, VT_UINT16, SET_NEVER),
    V(44, UInt32_input, VT_UINT32, SET_TUNABLE),
    V(45, UInt32_parameter, VT_UINT32, SET_TUNABLE),
    V(46, UInt32_output, VT_UINT32, SET_NEVER),
    V(47, Int64_input, VT_INT64, SET_TUNABLE),
    V(48, Int64_parameter, VT_INT64, SET_TUNABLE),
    V(49, Int64_output, VT_INT64, SET_NEVER),
    V(50, UInt64_input, VT_UINT64, SET_TUNABLE),
    V(51, UInt64_parameter, VT_UINT64, SET_TUNABLE),
    V(52, UInt64_output, VT_UINT64, SET_NEVER),
    V(53, Binary_output, VT_BINARY, SET_NEVER),
    V(54, sections, VT_UINT16, SET_STRUCTURAL),
#endif
};

const size_t MODEL_N_VARIABLES = sizeof MODEL_VARIABLES / sizeof MODEL_VARIABLES[0];
const size_t MODEL_DATA_SIZE = sizeof(Data);

void model_start(void *data)
{
    Data *m = data;
    m->gain = 2.0;
    m->offset = 0.5;
    m->step = 3;
    m->teeth = 19;
    m->invert = false;
    strcpy(m->label, "gear");
    m->mode = 2;
    m->Real_input = 1.0;
    m->Integer_input = 0;
    m->Boolean_input = false;
    strcpy(m->String_input, "abc");
    m->Enumeration_input = 1;
    m->Real_integral = 0.0;
    m->Float32_input = 0.25f;
    m->Int8_input = -3;
    m->Int8_parameter = 5;
    m->UInt8_input = 200;
    m->UInt8_parameter = 15;
    m->Int16_input = -1000;
    m->Int16_parameter = 77;
    m->UInt16_input = 60000;
    m->UInt16_parameter = 255;
    m->UInt32_input = 4000000000u;
    m->UInt32_parameter = 1;
    m->Int64_input = -9000000000000000000LL;
    m->Int64_parameter = 3;
    m->UInt64_input = 18000000000000000000ULL;
    m->UInt64_parameter = 1;
    m->sections = 4;
    m->t0 = 0.0;
}

int model_initialize(void *data, double t0, const char *resources, char *msg, size_t n)
{
    Data *m = data;
    char path[1024];
    FILE *f;
    size_t len;

    m->t0 = t0;
    m->Real_integral = 0.0;
    if (resources == NULL) {
        snprintf(msg, n, "no resources directory was given; message.txt is needed");
        return -1;
    }
    snprintf(path, sizeof path, "%smessage.txt", resources);
    f = fopen(path, "r");
    if (f == NULL) {
        snprintf(msg, n, "cannot open the resource %s", path);
        return -1;
    }
    if (fgets(m->resource_text, STRING_CAPACITY, f) == NULL)
        m->resource_text[0] = '\0';
    fclose(f);
    len = strcspn(m->resource_text, "\r\n");
    m->resource_text[len] = '\0';
    m->resource_length = (int32_t)len;
    return 0;
}

void model_outputs(void *data, double t)
{
    Data *m = data;
    m->time = t;
    size_t len;

    m->ratio = 2.0 * m->offset;
    m->Real_output = m->gain * m->Real_input + m->offset;
    m->Integer_output = m->Integer_input + m->step * (int32_t)floor(t - m->t0 + 1e-9);
    m->Boolean_output = m->Boolean_input != m->invert;
    snprintf(m->String_output, sizeof m->String_output, "%s:%s", m->label, m->String_input);
    m->Enumeration_output = m->Boolean_input ? m->Enumeration_input : m->mode;
    m->Float32_output = m->Float32_input * (float)m->gain;
    m->Int8_output = (int8_t)(m->Int8_input ^ m->Int8_parameter);
    m->UInt8_output = (uint8_t)(m->UInt8_input ^ m->UInt8_parameter);
    m->Int16_output = (int16_t)(m->Int16_input ^ m->Int16_parameter);
    m->UInt16_output = (uint16_t)(m->UInt16_input ^ m->UInt16_parameter);
    m->UInt32_output = m->UInt32_input ^ m->UInt32_parameter;
    m->Int64_output = m->Int64_input ^ m->Int64_parameter;
    m->UInt64_output = m->UInt64_input ^ m->UInt64_parameter;
    len = strlen(m->String_output);
    m->Binary_output.size = len < BINARY_CAPACITY ? len : BINARY_CAPACITY;
    memcpy(m->Binary_output.data, m->String_output, m->Binary_output.size);
}

int model_advance(void *data, double *t, double t_end, bool *terminate, char *msg, size_t n)
{
    Data *m = data;
    (void)msg;
    (void)n;
    /* the input is held over the step, so the integral is exact */
    m->Real_integral += m->gain * m->Real_input * (t_end - *t);
    *t = t_end;
    *terminate = false;
    return 0;
}
