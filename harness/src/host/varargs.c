/* The variadic functions of the OFX parameter and message suites. Stable Rust
 * cannot define C variadics, so these unpack the arguments by the param's
 * type (asked of the Rust host) and call plain Rust functions. */
#include <stdarg.h>
#include <stdio.h>

typedef int OfxStatus;
enum { KIND_DOUBLE = 0, KIND_INT = 1, KIND_STRING = 2 };
#define MAX_DIM 4

extern int mfx_param_shape(void *param, int *kind, int *dim);
extern int mfx_param_get(void *param, double time, int at_time, double *d, int *iv, const char **s);
extern int mfx_param_set(void *param, double time, int at_time, const double *d, const int *iv, const char *s);
extern int mfx_message_text(void *handle, const char *type, const char *id, const char *text);
extern int mfx_persistent_text(void *handle, const char *type, const char *id, const char *text);

static OfxStatus get_va(void *h, double time, int at_time, va_list ap) {
    int kind = 0, dim = 0, k;
    double d[MAX_DIM] = {0};
    int iv[MAX_DIM] = {0};
    const char *s = 0;
    OfxStatus st = mfx_param_shape(h, &kind, &dim);
    if (st) return st;
    st = mfx_param_get(h, time, at_time, d, iv, &s);
    if (st) return st;
    for (k = 0; k < dim && k < MAX_DIM; k++) {
        if (kind == KIND_DOUBLE) { double *o = va_arg(ap, double *); if (o) *o = d[k]; }
        else if (kind == KIND_INT) { int *o = va_arg(ap, int *); if (o) *o = iv[k]; }
        else { const char **o = va_arg(ap, const char **); if (o) *o = s; }
    }
    return 0;
}

static OfxStatus set_va(void *h, double time, int at_time, va_list ap) {
    int kind = 0, dim = 0, k;
    double d[MAX_DIM] = {0};
    int iv[MAX_DIM] = {0};
    const char *s = 0;
    OfxStatus st = mfx_param_shape(h, &kind, &dim);
    if (st) return st;
    for (k = 0; k < dim && k < MAX_DIM; k++) {
        if (kind == KIND_DOUBLE) d[k] = va_arg(ap, double);
        else if (kind == KIND_INT) iv[k] = va_arg(ap, int);
        else s = va_arg(ap, const char *);
    }
    return mfx_param_set(h, time, at_time, d, iv, s);
}

OfxStatus mfx_paramGetValue(void *h, ...) {
    va_list ap; va_start(ap, h);
    OfxStatus st = get_va(h, 0.0, 0, ap);
    va_end(ap); return st;
}
OfxStatus mfx_paramGetValueAtTime(void *h, double time, ...) {
    va_list ap; va_start(ap, time);
    OfxStatus st = get_va(h, time, 1, ap);
    va_end(ap); return st;
}
OfxStatus mfx_paramSetValue(void *h, ...) {
    va_list ap; va_start(ap, h);
    OfxStatus st = set_va(h, 0.0, 0, ap);
    va_end(ap); return st;
}
OfxStatus mfx_paramSetValueAtTime(void *h, double time, ...) {
    va_list ap; va_start(ap, time);
    OfxStatus st = set_va(h, time, 1, ap);
    va_end(ap); return st;
}
/* Derivatives and integrals of animated params are not provided by this host. */
OfxStatus mfx_paramGetDerivative(void *h, double time, ...) { (void)h; (void)time; return 5; /* kOfxStatErrUnsupported */ }
OfxStatus mfx_paramGetIntegral(void *h, double t1, double t2, ...) { (void)h; (void)t1; (void)t2; return 5; }

/* Armed as a misuse (host::misuse): the host loses a message's arguments,
 * as Natron 2.5 does (it passes the va_list on as if it were one argument).
 * The format is printed as such a host shows it: "%%" as "%", every other
 * conversion as nothing (Natron's "%s" tooltip read blank). */
extern int mfx_messages_lose_arguments(void);

static void format_without_arguments(const char *f, char *buf, size_t n) {
    size_t o = 0;
    while (*f && o + 1 < n) {
        if (*f != '%') { buf[o++] = *f++; continue; }
        f++;
        if (*f == '%') { buf[o++] = '%'; f++; continue; }
        /* flags, width, precision and length, then the conversion letter */
        while (*f && !((*f >= 'a' && *f <= 'z' && *f != 'h' && *f != 'l' && *f != 'j' &&
                        *f != 'z' && *f != 't') || (*f >= 'A' && *f <= 'Z' && *f != 'L')))
            f++;
        if (*f) f++;
    }
    buf[o] = 0;
}

static void format_message(char *buf, size_t n, const char *format, va_list ap) {
    if (!format) format = "";
    if (mfx_messages_lose_arguments()) format_without_arguments(format, buf, n);
    else vsnprintf(buf, n, format, ap);
}

OfxStatus mfx_message(void *handle, const char *type, const char *id, const char *format, ...) {
    char buf[4096];
    va_list ap; va_start(ap, format);
    format_message(buf, sizeof buf, format, ap);
    va_end(ap);
    return mfx_message_text(handle, type, id, buf);
}

OfxStatus mfx_persistent_message(void *handle, const char *type, const char *id, const char *format, ...) {
    char buf[4096];
    va_list ap; va_start(ap, format);
    format_message(buf, sizeof buf, format, ap);
    va_end(ap);
    return mfx_persistent_text(handle, type, id, buf);
}
