/* format_number.c - numbers to text without printf, for the files the
   `tiledtex` tool writes (an OBJ of 100k faces is over a million numbers, and
   printf("%.9g") was a fifth of `tiledtex tile`'s time). See tool.h.

   A float is printed with 9 significant digits, which is enough for every
   float to read back exactly, in the layout of printf("%.9g"): trailing zeros
   dropped, exponent form below 1e-4 and from 1e9 up. How:

     1. e = the decimal exponent of |x| (estimated from the binary one, then
        corrected), so that |x| = d.dddddddd * 10^e;
     2. m = |x| * 10^(8 - e), rounded to an integer of exactly 9 digits, in
        double precision: a float has 24 bits, so the product is exact or
        within 2^-52 of the truth, far inside the half unit of the 9th digit
        that round-tripping needs;
     3. the digits of m, two at a time from a table, placed around the point.

   The result is the same text as printf("%.9g") except, rarely, in the 9th
   digit when the exact value lies within about 1e-7 of a rounding tie;
   either text reads back as the same float. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "tool.h"

static const char digit_pairs[] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

/* 10^0 .. 10^60 (exact up to 10^22, correctly rounded beyond). */
static const double powers_of_ten[] = {
    1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
    1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22, 1e23, 1e24, 1e25, 1e26, 1e27, 1e28, 1e29, 1e30, 1e31,
    1e32, 1e33, 1e34, 1e35, 1e36, 1e37, 1e38, 1e39, 1e40, 1e41, 1e42, 1e43, 1e44, 1e45, 1e46, 1e47,
    1e48, 1e49, 1e50, 1e51, 1e52, 1e53, 1e54, 1e55, 1e56, 1e57, 1e58, 1e59, 1e60};

/* |x| * 10^(8 - e) rounded to an integer (ties to even, as printf). */
static uint64_t scaled_digits(double magnitude, int e)
{
    int k = 8 - e;
    double scaled = k >= 0 ? magnitude * powers_of_ten[k] : magnitude / powers_of_ten[-k];
    uint64_t m = (uint64_t)(scaled + 0.5);
    if ((double)m - scaled == 0.5 && (m & 1)) m--;     /* an exact tie: to even */
    return m;
}

int tool_format_float(float value, char *out)
{
    char digits[9], *p = out;
    double magnitude = (double)value;
    uint64_t m;
    uint32_t high, low;
    int binary_exponent, e, ndigits, i;

    if (!isfinite(value)) return snprintf(out, TOOL_NUMBER_TEXT_SIZE, "%.9g", (double)value);
    if (signbit(value)) {
        *p++ = '-';
        magnitude = -magnitude;
    }
    if (magnitude == 0.0) {
        *p++ = '0';
        *p = '\0';
        return (int)(p - out);
    }
    /* 1. log10(2) ~ 78913 / 2^18; the estimate is the true exponent or one
       below it (floats span about 10^-45 .. 10^38, well inside the table).
       The binary exponent is read off the float's bits (frexp for the
       subnormals, whose field is 0). */
    {
        uint32_t bits;
        memcpy(&bits, &value, sizeof bits);
        binary_exponent = (int)((bits >> 23) & 0xffu) - 127;   /* 2^be <= |x| < 2^(be+1) */
        if (binary_exponent == -127) {
            frexp(magnitude, &binary_exponent);
            binary_exponent -= 1;
        }
    }
    e = binary_exponent >= 0 ? (binary_exponent * 78913) >> 18 : -((-binary_exponent * 78913 + 262143) >> 18);
    /* 2. nine digits; a carry past them (999999999.7 -> 10^9) or an estimate
       one too low moves the exponent up, and the digits are made again. */
    m = scaled_digits(magnitude, e);
    while (m >= 1000000000u) m = scaled_digits(magnitude, ++e);
    while (m < 100000000u) m = scaled_digits(magnitude, --e);
    /* 3. the digits, most significant first */
    high = (uint32_t)(m / 10000u);                      /* 5 digits */
    low = (uint32_t)(m % 10000u);                       /* 4 digits */
    digits[0] = (char)('0' + high / 10000u);
    memcpy(digits + 1, digit_pairs + 2 * ((high / 100u) % 100u), 2);
    memcpy(digits + 3, digit_pairs + 2 * (high % 100u), 2);
    memcpy(digits + 5, digit_pairs + 2 * (low / 100u), 2);
    memcpy(digits + 7, digit_pairs + 2 * (low % 100u), 2);
    ndigits = 9;
    while (ndigits > 1 && digits[ndigits - 1] == '0') ndigits--;

    if (e < -4 || e >= 9) {                             /* d.ddde-05, d.ddde+10 */
        int exponent = e < 0 ? -e : e;
        *p++ = digits[0];
        if (ndigits > 1) {
            *p++ = '.';
            memcpy(p, digits + 1, (size_t)ndigits - 1);
            p += ndigits - 1;
        }
        *p++ = 'e';
        *p++ = e < 0 ? '-' : '+';
        memcpy(p, digit_pairs + 2 * exponent, 2);       /* |e| <= 45 */
        p += 2;
    } else if (e >= 0) {                                /* ddd.ddd */
        memcpy(p, digits, (size_t)e + 1);
        p += e + 1;
        if (ndigits > e + 1) {
            *p++ = '.';
            memcpy(p, digits + e + 1, (size_t)(ndigits - e - 1));
            p += ndigits - e - 1;
        }
    } else {                                            /* 0.000ddd */
        *p++ = '0';
        *p++ = '.';
        for (i = -1; i > e; i--) *p++ = '0';
        memcpy(p, digits, (size_t)ndigits);
        p += ndigits;
    }
    *p = '\0';
    return (int)(p - out);
}

int tool_format_int(long value, char *out)
{
    unsigned long magnitude = value < 0 ? 0ul - (unsigned long)value : (unsigned long)value, rest;
    int length = 0, ndigits = 1, i;
    if (value < 0) out[length++] = '-';
    for (rest = magnitude; rest >= 10u; rest /= 10u) ndigits++;
    /* The digits from the last, two at a time from the table. */
    i = length + ndigits;
    out[i] = '\0';
    while (magnitude >= 100u) {
        memcpy(out + i - 2, digit_pairs + 2 * (magnitude % 100u), 2);
        magnitude /= 100u;
        i -= 2;
    }
    if (magnitude >= 10u) memcpy(out + i - 2, digit_pairs + 2 * magnitude, 2);
    else out[i - 1] = (char)('0' + magnitude);
    return length + ndigits;
}

float tool_float_of(double value)
{
    /* FLT_MAX + half the step between floats there: (2 - 2^-24) 2^127, the
       tie, which rounds to even (up: FLT_MAX's last bit is odd). */
    const double overflows = 3.4028235677973366e+38;
    if (value >= overflows) return (float)INFINITY;
    if (value <= -overflows) return (float)-INFINITY;
    if (value > FLT_MAX) return FLT_MAX;
    if (value < -FLT_MAX) return -FLT_MAX;
    return (float)value;
}
