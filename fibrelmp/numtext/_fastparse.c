/* Optional C helpers for fibrelmp.post (built by setup.py at install time, else compiled on
 * first use by fastparse.py; a plain shared library loaded with ctypes, not a Python module).
 *
 * fp_parse_block: a block of whitespace-separated decimal numbers, exactly nrows lines of
 *   ncols tokens, into a row-major float64 array.  Correctly rounded (bit-identical to
 *   strtod / float() / np.loadtxt): Clinger's fast path (mantissa < 2^53, |exp10| <= 22:
 *   one exact multiply or divide), then (x86-64: 17-19 digit mantissas, as %.17g writes them)
 *   one x87 extended-precision multiply or divide rounded to double, unless that double
 *   rounding could differ (the extended result sits exactly on a halfway point), otherwise
 *   strtod on the token.  Anything unusual (inf,
 *   nan, hex, text, wrong token count, blank line, odd whitespace) returns -1 so that the
 *   caller uses its numpy path, which produces the result or the precise error.
 *
 * fp_parse_tagged: the same for a FibreNet model block (BEAD / SPRING / ANGLE lines): each line
 *   starts with a keyword and a name (type name, spring or angle kind) before the numbers;
 *   the name is stored as its index in a table.  Declines (-1) just as fp_parse_block does.
 *
 * fp_format_fixed_rows: rows of fixed-point columns (integer s / 10^k, exactly k decimals),
 *   each right-aligned in its column width, one space between columns: the bytes
 *   numtext.shortest.rows_text writes with numpy (data files).
 *
 * fp_format_g_rows: rows "\tname" + ncols x "\t%g" + "\n" (FibreNet restart files),
 *   byte-identical to printf / Python's %: the 6 significant digits are rounded on the exact
 *   binary value (an exact product, or a quotient checked by exact products; ties to even),
 *   printf itself only for |x| outside [1e-17, 1e28); non-finite values decline.
 *
 * fp_format_xyz: rows "name\t%.5f\t%.5f\t%.5f\n" byte-identical to printf: |x| 10^5 is
 *   split into an exact sum p + e (Dekker's product), so rounding (ties to even) is decided
 *   on the exact binary value, as glibc does.  Non-finite or |x| 10^5 >= 2^51 returns -1.
 *
 * Build flags must keep IEEE double semantics (no -ffast-math; -ffp-contract=off).
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <float.h>
#include <stdio.h>

#if !defined(FLT_EVAL_METHOD) || FLT_EVAL_METHOD != 0
#define FP_EXCESS_PRECISION 1     /* x87: the fast paths would double-round; decline everything */
#else
#define FP_EXCESS_PRECISION 0
#endif

static const double P10[23] = {
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
    1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/* x87 extended precision (64-bit significand): mantissa < 2^64 and 10^k, k <= 27, are exact
   there, so mant * 10^k or mant / 10^k is one correctly rounded operation; rounding that to
   double equals rounding the exact value unless the extended result is exactly halfway
   between two doubles (its low 11 significand bits are 10000000000b): then strtod decides. */
#if defined(__x86_64__) && defined(LDBL_MANT_DIG) && LDBL_MANT_DIG == 64
#define FP_EXTENDED 1
static const long double P10L[28] = {
    1e0L, 1e1L, 1e2L, 1e3L, 1e4L, 1e5L, 1e6L, 1e7L, 1e8L, 1e9L, 1e10L, 1e11L, 1e12L, 1e13L,
    1e14L, 1e15L, 1e16L, 1e17L, 1e18L, 1e19L, 1e20L, 1e21L, 1e22L, 1e23L, 1e24L, 1e25L, 1e26L,
    1e27L};
#else
#define FP_EXTENDED 0
#endif

#define MAXTOK 400

static inline int is_sep(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

/* strtod on the token [s, e) (correctly rounded); 0 ok, -1 if it is not all consumed */
static int slow_token(const char *s, const char *e, double *out)
{
    char buf[MAXTOK + 1];
    size_t len = (size_t)(e - s);
    if (len > MAXTOK) return -1;
    memcpy(buf, s, len);
    buf[len] = 0;
    char *end;
    *out = strtod(buf, &end);
    return end == buf + len ? 0 : -1;
}

/* parse the token at *pp matching [+-]digits[.digits][(e|E)[+-]digits] and ending at a
   separator or the end of the buffer; advances *pp; 0 ok, -1 otherwise */
static inline int parse_token(const char **pp, const char *e, double *out)
{
    const char *s = *pp, *p = s;
    int neg = 0;
    if (p < e && (*p == '+' || *p == '-')) {
        neg = (*p == '-');
        p++;
    }
    uint64_t mant = 0;
    const char *d0 = p;
    while (p < e && (unsigned)(*p - '0') < 10) {
        mant = mant * 10 + (unsigned)(*p - '0');      /* wraps if > 19 digits: see below */
        p++;
    }
    long ndig = p - d0, nfrac = 0;
    if (p < e && *p == '.') {
        p++;
        const char *f0 = p;
        while (p < e && (unsigned)(*p - '0') < 10) {
            mant = mant * 10 + (unsigned)(*p - '0');
            p++;
        }
        nfrac = p - f0;
        ndig += nfrac;
    }
    if (ndig == 0) return -1;
    long exp10 = -nfrac;
    if (p < e && (*p == 'e' || *p == 'E')) {
        p++;
        int eneg = 0;
        if (p < e && (*p == '+' || *p == '-')) {
            eneg = (*p == '-');
            p++;
        }
        if (!(p < e && (unsigned)(*p - '0') < 10)) return -1;
        long x = 0;
        while (p < e && (unsigned)(*p - '0') < 10) {
            if (x < 100000) x = x * 10 + (*p - '0');
            p++;
        }
        exp10 += eneg ? -x : x;
    }
    if (p < e && !is_sep(*p)) return -1;
    *pp = p;
#if FP_EXTENDED
    if (ndig <= 19 && exp10 >= -27 && exp10 <= 27 &&
        (mant >= (1ULL << 53) || exp10 < -22 || exp10 > 22)) {
        long double l = (long double)mant;                  /* exact: mant < 10^19 < 2^64 */
        l = exp10 < 0 ? l / P10L[-exp10] : l * P10L[exp10];
        uint64_t sig;
        memcpy(&sig, &l, sizeof sig);                       /* the 64-bit significand */
        if ((sig & 0x7FF) == 0x400) return slow_token(s, p, out);
        double v = (double)l;
        *out = neg ? -v : v;
        return 0;
    }
#endif
    if (ndig > 19 || mant >= (1ULL << 53) || exp10 < -22 || exp10 > 22)
        return slow_token(s, p, out);
    double v = (double)mant;           /* exact */
    if (exp10 < 0) v /= P10[-exp10];
    else if (exp10 > 0) v *= P10[exp10];
    *out = neg ? -v : v;
    return 0;
}

/* The numbers of one row from column col on into row[col..ncols), then its line end ('\n',
   "\r\n" or the buffer's end); 0, or -1 on a bad number or a wrong number of columns. */
static int parse_row_rest(const char **pp, const char *end, double *row, int64_t col, int64_t ncols)
{
    const char *p = *pp;
    for (;;) {
        while (p < end && (*p == ' ' || *p == '\t')) p++;
        if (p >= end || *p == '\n' || *p == '\r') break;
        if (col >= ncols) return -1;
        if (parse_token(&p, end, row + col)) return -1;
        col++;
    }
    if (col != ncols) return -1;
    if (p < end && *p == '\r') {
        p++;
        if (!(p < end && *p == '\n')) return -1;
    }
    if (p < end) p++;   /* '\n' */
    *pp = p;
    return 0;
}

/* 0 on success; -1: caller must use its own (numpy) path */
int fp_parse_block(const char *buf, int64_t len, double *out, int64_t nrows, int64_t ncols)
{
    const char *p = buf, *end = buf + len;
    int64_t row = 0;
    double *o = out;
    if (FP_EXCESS_PRECISION) return -1;
    while (row < nrows) {
        if (p >= end) return -1;
        if (parse_row_rest(&p, end, o, 0, ncols)) return -1;
        o += ncols;
        row++;
    }
    return p == end ? 0 : -1;
}

/* the token at *pp (up to a separator or the end): its start and length; advances *pp */
static inline int64_t word_token(const char **pp, const char *e, const char **start)
{
    const char *p = *pp;
    *start = p;
    while (p < e && !is_sep(*p)) p++;
    *pp = p;
    return (int64_t)(p - *start);
}

/* nrows lines "KEY NAME number ... number" (ncols tokens in all) into out (row-major, or with
   stride != 0 column-major: value c of row r at out[c * stride + r]): column 0 = 0,
   column 1 = index of NAME in names (nnames entries, each NUL-padded to w bytes), then the
   numbers as fp_parse_block reads them.  Leading spaces/tabs, a '\r' before '\n' and a
   missing last '\n' are accepted; anything else (blank lines, another keyword, an unknown
   name, a bad number, a wrong token count) returns -1. */
int fp_parse_tagged(const char *buf, int64_t len, const char *key, int64_t klen, const char *names,
                    int64_t nnames, int64_t w, double *out, int64_t nrows, int64_t ncols,
                    int64_t stride)
{
    const char *p = buf, *end = buf + len;
    double *o = out;
    double row_values[64];
    if (FP_EXCESS_PRECISION || ncols < 2 || ncols > 64) return -1;
    for (int64_t row = 0; row < nrows; row++) {
        if (p >= end) return -1;
        while (p < end && (*p == ' ' || *p == '\t')) p++;
        const char *t;
        int64_t n = word_token(&p, end, &t);
        if (n != klen || memcmp(t, key, (size_t)klen) != 0) return -1;
        while (p < end && (*p == ' ' || *p == '\t')) p++;
        n = word_token(&p, end, &t);
        if (n == 0 || n > w) return -1;
        int64_t which = -1;
        for (int64_t k = 0; k < nnames; k++) {
            const char *name = names + k * w;
            if (memcmp(t, name, (size_t)n) == 0 && (n == w || name[n] == 0)) {
                which = k;
                break;
            }
        }
        if (which < 0) return -1;
        double *v = stride ? row_values : o;
        v[0] = 0.0;
        v[1] = (double)which;
        if (parse_row_rest(&p, end, v, 2, ncols)) return -1;
        if (stride) {                       /* column-major: column c of row r at out[c * stride + r] */
            for (int64_t c = 0; c < ncols; c++) out[c * stride + row] = v[c];
        } else {
            o += ncols;
        }
    }
    return p == end ? 0 : -1;
}

/* ---------------------------------------------------------------- %.5f formatting */

static const double SPLIT = 134217729.0;   /* 2^27 + 1 */
static const double LIMIT = 2251799813685248.0;   /* 2^51 */

static inline int round_scaled(double x, double scale, int64_t *m)
{
    double a = fabs(x);
    double p = a * scale;
    if (!(p < LIMIT)) return -1;           /* also nan, inf */
    double c = SPLIT * a, ah = c - (c - a), al = a - ah;
    double cb = SPLIT * scale, bh = cb - (cb - scale), bl = scale - bh;
    double err = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
    int64_t r = (int64_t)p;                /* floor: 0 <= p < 2^51 */
    double f = p - (double)r;
    r += (f > 0.5);                        /* branch-free: f is random */
    if (f == 0.5) r += (err > 0 || (err == 0 && (r & 1)));
    *m = r;
    return 0;
}

static const char DIG2[201] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

static inline char *put_int(char *o, uint64_t ip)
{
    if (ip < 100) {                /* branch-free for the common 1-2 digit case */
        int two = ip >= 10;
        o[0] = DIG2[2 * ip + 1 - two];
        o[1] = DIG2[2 * ip + 1];
        return o + 1 + two;
    }
    int nd = 3;
    for (uint64_t t = 1000; nd < 20 && ip >= t; t *= 10) nd++;
    char *q = o + nd;
    while (ip >= 100) {
        unsigned r = (unsigned)(ip % 100);
        ip /= 100;
        *--q = DIG2[2 * r + 1];
        *--q = DIG2[2 * r];
    }
    if (ip >= 10) {
        *--q = DIG2[2 * ip + 1];
        *--q = DIG2[2 * ip];
    } else {
        *--q = (char)('0' + ip);
    }
    return o + nd;
}

static inline char *put_fixed(char *o, double x, int64_t m, int decimals, int64_t unit)
{
    *o = '-';
    o += signbit(x) != 0;
    if (decimals == 5) {            /* the xyz case: constant divisors */
        uint64_t ip = (uint64_t)m / 100000u;
        unsigned fr = (unsigned)((uint64_t)m - ip * 100000u);
        o = put_int(o, ip);
        o[0] = '.';
        unsigned a = fr / 1000u, b = (fr / 10u) % 100u;
        o[1] = DIG2[2 * a];
        o[2] = DIG2[2 * a + 1];
        o[3] = DIG2[2 * b];
        o[4] = DIG2[2 * b + 1];
        o[5] = (char)('0' + fr % 10u);
        return o + 6;
    }
    int64_t ip = m / unit, fr = m - ip * unit;
    o = put_int(o, (uint64_t)ip);
    if (decimals) {
        *o++ = '.';
        for (int j = decimals - 1; j >= 0; j--) {
            o[j] = (char)('0' + fr % 10);
            fr /= 10;
        }
        o += decimals;
    }
    return o;
}

/* rows name[codes[i]] \t v[i,0] \t v[i,1] \t v[i,2] \n into out (capacity cap);
   returns bytes written or -1 (fall back). names: nnames entries of width namew, NUL-padded */
int64_t fp_format_xyz(const int64_t *codes, const double *vals, int64_t n, const char *names,
                      int64_t nnames, int64_t namew, int decimals, char *out, int64_t cap)
{
    double scale = 1.0;
    int64_t unit = 1;
    if (FP_EXCESS_PRECISION || decimals < 0 || decimals > 9) return -1;
    for (int j = 0; j < decimals; j++) {
        scale *= 10.0;
        unit *= 10;
    }
    char *o = out, *stop = out + cap;
    for (int64_t i = 0; i < n; i++) {
        /* worst case per row: name + 3 * (sign + 16 digits + '.' + decimals) + 4 separators */
        if (stop - o < namew + 3 * (28 + decimals) + 4) return -1;
        int64_t c = codes[i];
        if (c < 0 || c >= nnames) return -1;
        const char *nm = names + c * namew;
        for (int64_t j = 0; j < namew && nm[j]; j++) *o++ = nm[j];
        for (int k = 0; k < 3; k++) {
            double x = vals[3 * i + k];
            int64_t m;
            if (round_scaled(x, scale, &m)) return -1;
            *o++ = '\t';
            o = put_fixed(o, x, m, decimals, unit);
        }
        *o++ = '\n';
    }
    return (int64_t)(o - out);
}

/* number of '\n' in buf[0, len) */
int64_t fp_count_lines(const char *buf, int64_t len)
{
    int64_t c = 0;
    const char *p = buf, *end = buf + len;
    while (p < end) {
        const char *q = memchr(p, '\n', (size_t)(end - p));
        if (!q) break;
        c++;
        p = q + 1;
    }
    return c;
}

/* offset of the need-th '\n' in buf[0, len) (need >= 1), or -1 with *found = how many */
int64_t fp_nth_newline(const char *buf, int64_t len, int64_t need, int64_t *found)
{
    int64_t c = 0;
    const char *p = buf, *end = buf + len;
    while (p < end) {
        const char *q = memchr(p, '\n', (size_t)(end - p));
        if (!q) break;
        if (++c == need) {
            *found = c;
            return (int64_t)(q - buf);
        }
        p = q + 1;
    }
    *found = c;
    return -1;
}

/* ---------------------------------------------------------------- fixed-point rows */

/* Row r: for each column c, the integer s = vals[r * ncols + c] printed as |s| / 10^k[c] with
   exactly k[c] decimals (at least k[c] + 1 digits), '-' before the first digit if s < 0,
   right-aligned in width[c]; columns separated by one space, rows ended by '\n'.  width[c]
   must hold the widest field of the column (the caller computes it).  Returns the bytes
   written, or -1 if a field is wider than its column or out would overflow. */
int64_t fp_format_fixed_rows(const int64_t *vals, int64_t nrows, int64_t ncols, const int64_t *k,
                             const int64_t *width, char *out, int64_t cap)
{
    int64_t rowlen = 0;
    for (int64_t c = 0; c < ncols; c++) {
        if (k[c] < 0 || k[c] > 18 || width[c] < 1 || width[c] > 40) return -1;
        rowlen += width[c] + 1;
    }
    if (rowlen * nrows > cap) return -1;
    char *o = out;
    char digits[24];
    for (int64_t r = 0; r < nrows; r++) {
        for (int64_t c = 0; c < ncols; c++) {
            int64_t s = vals[r * ncols + c];
            uint64_t mag = s < 0 ? (uint64_t)0 - (uint64_t)s : (uint64_t)s;
            int nd = 0;                              /* digits of mag (reversed), >= k + 1 */
            while (mag >= 100) {
                unsigned two = (unsigned)(mag % 100);
                mag /= 100;
                digits[nd++] = DIG2[2 * two + 1];
                digits[nd++] = DIG2[2 * two];
            }
            if (mag >= 10) {
                digits[nd++] = DIG2[2 * mag + 1];
                digits[nd++] = DIG2[2 * mag];
            } else {
                digits[nd++] = (char)('0' + mag);
            }
            while (nd < k[c] + 1) digits[nd++] = '0';
            int64_t len = nd + (s < 0) + (k[c] > 0);
            if (len > width[c]) return -1;
            for (int64_t pad = width[c] - len; pad > 0; pad--) *o++ = ' ';
            if (s < 0) *o++ = '-';
            for (int j = nd - 1; j >= 0; j--) {
                *o++ = digits[j];
                if (j == k[c] && k[c] > 0) *o++ = '.';
            }
            *o++ = c + 1 < ncols ? ' ' : '\n';
        }
    }
    return (int64_t)(o - out);
}

/* ---------------------------------------------------------------- %g rows */

/* u * d = p + (returned) exactly (Dekker's product; u, d > 0 and moderate) */
static inline double prod_err(double u, double d, double p)
{
    double c = SPLIT * u, uh = c - (c - u), ul = u - uh;
    double cd = SPLIT * d, dh = cd - (cd - d), dl = d - dh;
    return ((uh * dh - p) + uh * dl + ul * dh) + ul * dl;
}

/* sign of a - u * d, exactly (a, u, d > 0) */
static inline int cmp_prod(double a, double u, double d)
{
    double p = u * d;
    if (a > 2.0 * p || a < 0.5 * p) return a > p ? 1 : -1;
    double diff = a - p;                   /* exact (Sterbenz) */
    double err = prod_err(u, d, p);
    return diff > err ? 1 : (diff < err ? -1 : 0);
}

/* *m = a / d rounded to the nearest integer, ties to even, decided exactly (d = 10^j) */
static inline int round_div(double a, double d, int64_t *m)
{
    double q = a / d;
    if (!(q < LIMIT)) return -1;
    int64_t c = (int64_t)(q + 0.5);
    for (int iter = 0; iter < 4; iter++) {
        int hi = cmp_prod(a, (double)c + 0.5, d);
        if (hi > 0) { c++; continue; }
        int lo = c > 0 ? cmp_prod(a, (double)c - 0.5, d) : 1;
        if (lo < 0) { c--; continue; }
        if ((hi == 0 || lo == 0) && (c & 1)) c += hi == 0 ? 1 : -1;
        *m = c;
        return 0;
    }
    return -1;
}

/* printf("%g", x) (6 significant digits, trailing zeros removed) into o; the length */
static int format_g6(double x, char *o)
{
    char *start = o;
    if (signbit(x)) {
        *o++ = '-';
        x = -x;
    }
    if (x == 0.0) {
        *o++ = '0';
        return (int)(o - start);
    }
    int64_t m = 0;
    int e = 0, ok = x >= 1e-17 && x < 1e28;
    if (ok) {
        int b;
        frexp(x, &b);
        e = (int)floor((b - 1) * 0.30102999566398120);     /* floor(log10 x), maybe 1 low */
        for (int tries = 0;; tries++) {
            int k = 5 - e;
            if (tries > 3 || k > 22 || k < -22 ||
                (k >= 0 ? round_scaled(x, P10[k], &m) : round_div(x, P10[-k], &m))) {
                ok = 0;
                break;
            }
            if (m >= 1000000) e++;
            else if (m < 100000) e--;
            else break;
        }
    }
    if (!ok) {                                   /* tiny or huge: the C library */
        int n = snprintf(o, 32, "%g", x);
        return n < 0 ? -1 : (int)(o - start) + n;
    }
    char d[6];
    for (int j = 5; j >= 0; j--) {
        d[j] = (char)('0' + m % 10);
        m /= 10;
    }
    int last = 5;                                /* last significant digit kept */
    if (e >= -4 && e < 6) {                      /* fixed notation, 5 - e decimals */
        if (e >= 0) {
            for (int j = 0; j <= e; j++) *o++ = d[j];
            while (last > e && d[last] == '0') last--;
            if (last > e) {
                *o++ = '.';
                for (int j = e + 1; j <= last; j++) *o++ = d[j];
            }
        } else {
            *o++ = '0';
            *o++ = '.';
            for (int j = 0; j < -e - 1; j++) *o++ = '0';
            while (last > 0 && d[last] == '0') last--;
            for (int j = 0; j <= last; j++) *o++ = d[j];
        }
    } else {                                     /* exponent notation */
        *o++ = d[0];
        while (last > 0 && d[last] == '0') last--;
        if (last > 0) {
            *o++ = '.';
            for (int j = 1; j <= last; j++) *o++ = d[j];
        }
        *o++ = 'e';
        *o++ = e < 0 ? '-' : '+';
        int ae = e < 0 ? -e : e;
        if (ae >= 100) *o++ = (char)('0' + ae / 100);
        *o++ = (char)('0' + ae / 10 % 10);
        *o++ = (char)('0' + ae % 10);
    }
    return (int)(o - start);
}

/* Row i: '\t', names[codes[i]] (NUL-padded to w bytes), then "\t%g" for each of the ncols
   values, '\n'.  Returns the bytes written, or -1 (a non-finite value, or out too small). */
int64_t fp_format_g_rows(const int64_t *codes, const double *vals, int64_t n, int64_t ncols,
                         const char *names, int64_t nnames, int64_t w, char *out, int64_t cap)
{
    char *o = out, *end = out + cap;
    if (FP_EXCESS_PRECISION) return -1;
    for (int64_t i = 0; i < n; i++) {
        int64_t c = codes[i];
        if (c < 0 || c >= nnames) return -1;
        const char *name = names + c * w;
        int64_t len = 0;
        while (len < w && name[len]) len++;
        if (end - o < len + 1 + ncols * 32 + 1) return -1;
        *o++ = '\t';
        memcpy(o, name, (size_t)len);
        o += len;
        for (int64_t k = 0; k < ncols; k++) {
            double x = vals[i * ncols + k];
            if (!isfinite(x)) return -1;
            *o++ = '\t';
            int m = format_g6(x, o);
            if (m < 0 || m >= 31) return -1;
            o += m;
        }
        *o++ = '\n';
    }
    return (int64_t)(o - out);
}

/* Rows of ncols values, each value its prefix (prefixes + k * w, NUL-padded to w bytes), then
   printf("%g"), then a space; a '\n' after every per_line rows (MUSEN's text export: "2 t 12 x y
   z ..." per time point, a line per object).  Returns the bytes written, or -1 (a non-finite
   value, or out too small). */
int64_t fp_format_g_template(const double *vals, int64_t nrows, int64_t ncols, const char *prefixes,
                             int64_t w, int64_t per_line, char *out, int64_t cap)
{
    char *o = out, *end = out + cap;
    if (FP_EXCESS_PRECISION || per_line < 1) return -1;
    for (int64_t i = 0; i < nrows; i++) {
        if (end - o < ncols * (w + 33) + 1) return -1;
        for (int64_t k = 0; k < ncols; k++) {
            const char *pre = prefixes + k * w;
            for (int64_t j = 0; j < w && pre[j]; j++) *o++ = pre[j];
            double x = vals[i * ncols + k];
            if (!isfinite(x)) return -1;
            int m = format_g6(x, o);
            if (m < 0 || m >= 31) return -1;
            o += m;
            *o++ = ' ';
        }
        if ((i + 1) % per_line == 0) *o++ = '\n';
    }
    return (int64_t)(o - out);
}

/* ---- MUSEN .mdem time points (protobuf wire format of ProtoTimePoint) -------------------
   A time point is "1: double time" and "2: repeated ProtoTimeDependentProperties", one per
   object.  An object's fields go to 34 columns (absent = 0, as protobuf reads them):
     0-2 coord (1)  3-5 angles (2)  6-8 vel (3)  9-11 angle_vel (4)  12-14 angle_accl (6)
     15 total_torque (8)  16 temperature (9)  17 liquid_film_mass (10)  18-20 force (11)
     21-24 quaternion (12)  25-33 stress_tensor (13: three vectors)
   and bit f of mask[i] says field f was on the wire.  Unknown fields are skipped. */
#define TD_COLS 34

static int pb_varint(const unsigned char **pp, const unsigned char *end, uint64_t *v)
{
    const unsigned char *p = *pp;
    uint64_t x = 0;
    for (int shift = 0; shift < 64; shift += 7) {
        if (p >= end) return -1;
        unsigned char b = *p++;
        x |= (uint64_t)(b & 0x7F) << shift;
        if (!(b & 0x80)) {
            *v = x;
            *pp = p;
            return 0;
        }
    }
    return -1;
}

static double pb_double(const unsigned char *p)
{
    double d;
    memcpy(&d, p, 8);           /* little endian hosts only (checked by the loader) */
    return d;
}

/* skip a field of wire type wt; 0 or -1 */
static int pb_skip(const unsigned char **pp, const unsigned char *end, int wt)
{
    uint64_t n;
    switch (wt) {
    case 0: return pb_varint(pp, end, &n);
    case 1: if (end - *pp < 8) return -1; *pp += 8; return 0;
    case 5: if (end - *pp < 4) return -1; *pp += 4; return 0;
    case 2:
        if (pb_varint(pp, end, &n) || (uint64_t)(end - *pp) < n) return -1;
        *pp += n;
        return 0;
    default: return -1;
    }
}

/* doubles 1..k of a message (ProtoVector k=3, ProtoQuaternion k=4) into out[0..k) */
static int pb_doubles(const unsigned char *p, const unsigned char *end, double *out, int k)
{
    while (p < end) {
        uint64_t tag;
        if (pb_varint(&p, end, &tag)) return -1;
        int f = (int)(tag >> 3), wt = (int)(tag & 7);
        if (f >= 1 && f <= k && wt == 1) {
            if (end - p < 8) return -1;
            out[f - 1] = pb_double(p);
            p += 8;
        } else if (pb_skip(&p, end, wt)) {
            return -1;
        }
    }
    return 0;
}

static int pb_object(const unsigned char *p, const unsigned char *end, double *row, uint32_t *mask)
{
    static const int vec_col[14] = {-1, 0, 3, 6, 9, -1, 12, -1, -1, -1, -1, 18, -1, -1};
    while (p < end) {
        uint64_t tag, n;
        if (pb_varint(&p, end, &tag)) return -1;
        int f = (int)(tag >> 3), wt = (int)(tag & 7);
        if (wt == 2 && f >= 1 && f <= 13 && (vec_col[f] >= 0 || f == 12 || f == 13)) {
            if (pb_varint(&p, end, &n) || (uint64_t)(end - p) < n) return -1;
            const unsigned char *sub = p, *subend = p + n;
            p = subend;
            if (f == 12) {
                if (pb_doubles(sub, subend, row + 21, 4)) return -1;
            } else if (f == 13) {                     /* ProtoMatrix: v1 v2 v3 */
                while (sub < subend) {
                    uint64_t t2, m;
                    if (pb_varint(&sub, subend, &t2)) return -1;
                    int g = (int)(t2 >> 3), w2 = (int)(t2 & 7);
                    if (g >= 1 && g <= 3 && w2 == 2) {
                        if (pb_varint(&sub, subend, &m) || (uint64_t)(subend - sub) < m) return -1;
                        if (pb_doubles(sub, sub + m, row + 25 + 3 * (g - 1), 3)) return -1;
                        sub += m;
                    } else if (pb_skip(&sub, subend, w2)) {
                        return -1;
                    }
                }
            } else if (pb_doubles(sub, subend, row + vec_col[f], 3)) {
                return -1;
            }
            *mask |= 1u << f;
        } else if (wt == 1 && f >= 8 && f <= 10) {
            if (end - p < 8) return -1;
            row[15 + (f - 8)] = pb_double(p);
            p += 8;
            *mask |= 1u << f;
        } else if (pb_skip(&p, end, wt)) {
            return -1;
        }
    }
    return 0;
}

/* Number of objects in a serialized ProtoTimePoint, or -1 if it is malformed. */
int64_t fp_mdem_count(const unsigned char *buf, int64_t len)
{
    const unsigned char *p = buf, *end = buf + len;
    int64_t n = 0;
    while (p < end) {
        uint64_t tag;
        if (pb_varint(&p, end, &tag)) return -1;
        if ((tag >> 3) == 2 && (tag & 7) == 2) n++;
        if (pb_skip(&p, end, (int)(tag & 7))) return -1;
    }
    return n;
}

/* Decode a ProtoTimePoint of n objects (fp_mdem_count) into time, out (n x 34, zeroed by the
   caller) and mask (n, zeroed); 0, or -1 if malformed. */
int fp_mdem_decode(const unsigned char *buf, int64_t len, double *time, double *out,
                   uint32_t *mask, int64_t n)
{
    const unsigned char *p = buf, *end = buf + len;
    int64_t i = 0;
    while (p < end) {
        uint64_t tag, m;
        if (pb_varint(&p, end, &tag)) return -1;
        if (tag > 0xFFFFFFFFu || (tag >> 3) > 0x1FFFFFFFu) return -1;   /* not a protobuf field */
        int f = (int)(tag >> 3), wt = (int)(tag & 7);
        if (f == 1 && wt == 1) {
            if (end - p < 8) return -1;
            *time = pb_double(p);
            p += 8;
        } else if (f == 2 && wt == 2) {
            if (pb_varint(&p, end, &m) || (uint64_t)(end - p) < m || i >= n) return -1;
            if (pb_object(p, p + m, out + i * TD_COLS, mask + i)) return -1;
            p += m;
            i++;
        } else if (pb_skip(&p, end, wt)) {
            return -1;
        }
    }
    return i == n ? 0 : -1;
}

static unsigned char *pb_put_varint(unsigned char *o, uint64_t v)
{
    while (v >= 0x80) {
        *o++ = (unsigned char)(v | 0x80);
        v >>= 7;
    }
    *o++ = (unsigned char)v;
    return o;
}

static int pb_varint_len(uint64_t v)
{
    int n = 1;
    while (v >= 0x80) {
        v >>= 7;
        n++;
    }
    return n;
}

static int nonzero(double x)        /* proto3 writes a double unless its bits are all zero */
{
    uint64_t u;
    memcpy(&u, &x, 8);
    return u != 0;
}

static int doubles_len(const double *v, int k)
{
    int n = 0;
    for (int j = 0; j < k; j++) n += nonzero(v[j]) ? 9 : 0;
    return n;
}

static unsigned char *put_doubles(unsigned char *o, const double *v, int k)
{
    for (int j = 0; j < k; j++) {
        if (!nonzero(v[j])) continue;
        *o++ = (unsigned char)(((j + 1) << 3) | 1);
        memcpy(o, v + j, 8);
        o += 8;
    }
    return o;
}

static int object_len(const double *row, uint32_t mask)
{
    static const int cols[14] = {-1, 0, 3, 6, 9, -1, 12, -1, 15, 16, 17, 18, 21, 25};
    int n = 0;
    for (int f = 1; f <= 13; f++) {
        if (!(mask & (1u << f)) || cols[f] < 0) continue;
        const double *v = row + cols[f];
        if (f >= 8 && f <= 10) {
            n += nonzero(v[0]) ? 9 : 0;
        } else if (f == 13) {
            int m = 0;
            for (int g = 0; g < 3; g++) {
                int s = doubles_len(v + 3 * g, 3);
                m += 1 + pb_varint_len((uint64_t)s) + s;
            }
            n += 1 + pb_varint_len((uint64_t)m) + m;
        } else {
            int s = doubles_len(v, f == 12 ? 4 : 3);
            n += 1 + pb_varint_len((uint64_t)s) + s;
        }
    }
    return n;
}

/* Serialize a ProtoTimePoint as protobuf does: time, then for object i a
   ProtoTimeDependentProperties with the fields whose bit is set in mask[i] (a message field
   is written even when all its values are 0, as after MUSEN's mutable_...(); a double only
   when non-zero).  Returns the bytes written, or -1 if cap is too small. */
int64_t fp_mdem_encode(double time, const double *vals, const uint32_t *mask, int64_t n,
                       unsigned char *out, int64_t cap)
{
    static const int cols[14] = {-1, 0, 3, 6, 9, -1, 12, -1, 15, 16, 17, 18, 21, 25};
    unsigned char *o = out, *end = out + cap;
    if (end - o < 9) return -1;
    if (nonzero(time)) {
        *o++ = 0x09;
        memcpy(o, &time, 8);
        o += 8;
    }
    for (int64_t i = 0; i < n; i++) {
        const double *row = vals + i * TD_COLS;
        uint32_t mk = mask[i];
        int len = object_len(row, mk);
        if (end - o < 1 + 10 + len) return -1;
        *o++ = 0x12;
        o = pb_put_varint(o, (uint64_t)len);
        for (int f = 1; f <= 13; f++) {
            if (!(mk & (1u << f)) || cols[f] < 0) continue;
            const double *v = row + cols[f];
            if (f >= 8 && f <= 10) {
                if (nonzero(v[0])) {
                    *o++ = (unsigned char)((f << 3) | 1);
                    memcpy(o, v, 8);
                    o += 8;
                }
            } else if (f == 13) {
                int m = 0;
                for (int g = 0; g < 3; g++) {
                    int s = doubles_len(v + 3 * g, 3);
                    m += 1 + pb_varint_len((uint64_t)s) + s;
                }
                *o++ = (unsigned char)((f << 3) | 2);
                o = pb_put_varint(o, (uint64_t)m);
                for (int g = 0; g < 3; g++) {
                    *o++ = (unsigned char)(((g + 1) << 3) | 2);
                    o = pb_put_varint(o, (uint64_t)doubles_len(v + 3 * g, 3));
                    o = put_doubles(o, v + 3 * g, 3);
                }
            } else {
                int k = f == 12 ? 4 : 3;
                *o++ = (unsigned char)((f << 3) | 2);
                o = pb_put_varint(o, (uint64_t)doubles_len(v, k));
                o = put_doubles(o, v, k);
            }
        }
    }
    return (int64_t)(o - out);
}

/* ---- MUSEN .mdem block descriptors (field 3 of ProtoSimulationStorage) -------------------
   A ProtoBlockDescriptor is "1: double start_time, 2: int64 offset_in_file, 3: int32 size,
   4: int32 uncompressed_size, 5: enum format".  fp_mdem_blocks walks the top level of a
   serialized ProtoSimulationStorage and, for each descriptor record (in wire order), stores
   start[i] and ints[k cap + i] (k = 0..3) = offset, size, uncompressed size, format, as
   protobuf converts them (the last occurrence of a field wins; int32 fields keep the low 32
   bits, sign-extended).  Consecutive descriptor records are merged into byte spans
   [spans[2 j], spans[2 j + 1]) so that the caller can cut them out of the message.
   With cap == 0 it only counts (descriptors, and spans in *nspans).  Returns the number of descriptors (and *nspans), or -1 on
   anything protobuf might read otherwise (malformed wire data, groups, a descriptor field of
   an unexpected number or wire type): the caller then parses the message with protobuf. */
static int pb_descriptor(const unsigned char *p, const unsigned char *end, double *start,
                         int64_t *ints, int64_t stride)
{
    double t = 0.0;
    int64_t v[4] = {0, 0, 0, 0};
    while (p < end) {
        uint64_t tag, x;
        if (pb_varint(&p, end, &tag)) return -1;
        int f = (int)(tag >> 3), wt = (int)(tag & 7);
        if (f == 1 && wt == 1) {
            if (end - p < 8) return -1;
            t = pb_double(p);
            p += 8;
        } else if (f >= 2 && f <= 5 && wt == 0) {
            if (pb_varint(&p, end, &x)) return -1;
            v[f - 2] = f == 2 ? (int64_t)x : (int64_t)(int32_t)(uint32_t)x;
        } else {
            return -1;
        }
    }
    if (start) {
        *start = t;
        for (int k = 0; k < 4; k++) ints[k * stride] = v[k];
    }
    return 0;
}

int64_t fp_mdem_blocks(const unsigned char *buf, int64_t len, double *start, int64_t *ints,
                       int64_t cap, int64_t *spans, int64_t *nspans)
{
    const unsigned char *p = buf, *end = buf + len;
    int64_t n = 0, m = 0, last_end = -1;
    while (p < end) {
        const unsigned char *rec = p;
        uint64_t tag, size;
        if (pb_varint(&p, end, &tag)) return -1;
        if (tag > 0xFFFFFFFFu || (tag >> 3) > 0x1FFFFFFFu) return -1;   /* not a protobuf field */
        int f = (int)(tag >> 3), wt = (int)(tag & 7);
        if (f == 0) return -1;
        if (f != 3) {
            if (pb_skip(&p, end, wt)) return -1;
            continue;
        }
        if (wt != 2 || pb_varint(&p, end, &size) || (uint64_t)(end - p) < size) return -1;
        int fill = cap > 0;
        if (fill && n >= cap) return -1;
        if (pb_descriptor(p, p + size, fill ? start + n : NULL, fill ? ints + n : NULL, cap))
            return -1;
        p += size;
        if (last_end == (int64_t)(rec - buf)) {
            if (fill) spans[2 * (m - 1) + 1] = (int64_t)(p - buf);
        } else {
            if (fill) {
                spans[2 * m] = (int64_t)(rec - buf);
                spans[2 * m + 1] = (int64_t)(p - buf);
            }
            m++;
        }
        last_end = (int64_t)(p - buf);
        n++;
    }
    if (nspans) *nspans = m;
    return n;
}

/* Serialize n ProtoBlockDescriptors as field-3 records of a ProtoSimulationStorage, byte for
   byte as protobuf writes them (fields in number order; a double unless its bits are all
   zero, an integer unless 0; int32 values sign-extended to 64 bits; format kZippedProtoBuff
   or the given fmt).  Returns the bytes written, or -1 if cap is too small. */
int64_t fp_mdem_put_blocks(const double *start, const int64_t *offset, const int64_t *size,
                           const int64_t *raw, int64_t fmt, int64_t n, unsigned char *out,
                           int64_t cap)
{
    unsigned char *o = out, *end = out + cap;
    for (int64_t i = 0; i < n; i++) {
        unsigned char body[64], *b = body;
        if (nonzero(start[i])) {
            *b++ = 0x09;
            memcpy(b, start + i, 8);
            b += 8;
        }
        const int64_t ints[4] = {offset[i], size[i], raw[i], fmt};
        for (int f = 0; f < 4; f++) {
            if (!ints[f]) continue;
            *b++ = (unsigned char)((f + 2) << 3);
            b = pb_put_varint(b, (uint64_t)ints[f]);
        }
        int64_t len = b - body;
        if (end - o < 2 + len) return -1;
        *o++ = 0x1a;                    /* field 3, length-delimited */
        *o++ = (unsigned char)len;      /* < 128 */
        memcpy(o, body, (size_t)len);
        o += len;
    }
    return (int64_t)(o - out);
}

/* ------------------------------------------------------------------------------------------
   MUSEN's CMatrix3::GetPrincipalStresses (Matrix3.h, e0ff360) of n row-major 3x3 tensors into
   n x 3 values: the closed trigonometric form on the upper triangle, operation for operation
   (pow(x, 3.), sqrt, fmin/fmax, acos, cos of the C library), as fibrelmp.granular_run.stress's
   Python fallback computes it.  An all-zero row gives 0 0 0 without evaluating the form. */
void fp_principal_stresses(const double *s, int64_t n, double *out)
{
    const double pi = 3.14159265358979323846;
    for (int64_t r = 0; r < n; r++) {
        const double *m = s + 9 * r;
        double *o = out + 3 * r;
        int any = 0;
        for (int k = 0; k < 9; k++) any |= m[k] != 0;
        if (!any) {
            o[0] = o[1] = o[2] = 0.0;
            continue;
        }
        const double a = m[0], b = m[4], c = m[8], d = m[1], e = m[2], f = m[5];
        const double i1 = a + b + c;
        /* pow(x, 2.) as x * x: what GCC compiles MUSEN's pow(x, 2.) to (cmusen's digits; the
           C library's pow differs in the last bit for some x) */
        const double i2 = a * b + b * c + c * a - d * d - e * e - f * f;
        const double i3 = a * b * c - a * (f * f) - b * (e * e) - c * (d * d) + 2 * d * e * f;
        const double q = fmin((3 * i2 - i1 * i1) / 9.0, 0.0);
        const double rr = (2 * pow(i1, 3.) - 9 * i1 * i2 + 27 * i3) / 54;
        const double g = fmin(fmax(rr / sqrt(pow(-q, 3.)), -1.), 1.);
        const double te = acos(g);
        o[0] = 2 * sqrt(-q) * cos(te / 3) + i1 / 3.;
        o[1] = 2 * sqrt(-q) * cos((te + 2 * pi) / 3) + i1 / 3.;
        o[2] = 2 * sqrt(-q) * cos((te + 4 * pi) / 3) + i1 / 3.;
    }
}
