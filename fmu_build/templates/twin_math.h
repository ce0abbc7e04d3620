/* Inline min/max for the generated model code.
 * CasADi emits fmax/fmin, which gcc calls through the PLT because of their NaN rules; the
 * mesh model evaluates ~70 of them per right-hand side, so the calls cost ~20 % of the run
 * time. A NaN state is caught after every step by the wrapper anyway. */
#ifndef TWIN_MATH_H
#define TWIN_MATH_H
#include <math.h>
static inline double twin_fmax(double a, double b) { return a > b ? a : b; }
static inline double twin_fmin(double a, double b) { return a < b ? a : b; }
#define fmax twin_fmax
#define fmin twin_fmin
#endif
