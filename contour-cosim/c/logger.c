/* The FMI 2.0 logger callback of contour-cosim. FMUs pass a printf format and its
 * arguments; stable Rust can declare but not define a variadic function, so this formats
 * the message (vsnprintf) and hands the text to the Rust sink the component environment
 * points to. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

/* The head of the Rust side's LogSink (#[repr(C)]). */
typedef struct {
    void (*receive)(const void *sink, const char *instance, unsigned status,
                    const char *category, const char *text);
} contour_cosim_sink;

void contour_cosim_logger(void *environment, const char *instance, unsigned status,
                          const char *category, const char *message, ...) {
    const contour_cosim_sink *sink = environment;
    if (sink == NULL || message == NULL) {
        return;
    }
    va_list args, again;
    va_start(args, message);
    va_copy(again, args);
    int length = vsnprintf(NULL, 0, message, args);
    va_end(args);
    char *text = length >= 0 ? malloc((size_t)length + 1) : NULL;
    if (text != NULL) {
        vsnprintf(text, (size_t)length + 1, message, again);
    }
    va_end(again);
    /* A format the C library cannot apply is passed on as it came. */
    sink->receive(sink, instance, status, category, text != NULL ? text : message);
    free(text);
}
