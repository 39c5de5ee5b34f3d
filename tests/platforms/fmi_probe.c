/* fmi_probe: calls an FMU's library as a script on the command line says and prints every
 * call's status, every log message and every value read, in a form that compares across
 * platforms (reals as the hex digits of their bits). Built for linux64 (gcc), win64
 * (mingw-w64, run under Wine) and aarch64-linux (gcc-aarch64-linux-gnu, run under QEMU) by
 * tests/platforms/test_platforms.py, which compares the transcripts.
 *
 *   fmi_probe LIBRARY COMMAND...
 *     inst NAME GUID URI|-      fmi2Instantiate (Co-Simulation, logging on; '-' is NULL)
 *     inst-no-callbacks GUID    fmi2Instantiate with NULL callback functions
 *     setup T0 | enter | exit | terminate | reset | free
 *     setr VR VALUE             fmi2SetReal (VALUE as strtod reads it: nan, inf too)
 *     seti VR VALUE | setb VR 0|1 | sets VR TEXT
 *     getr VR | geti VR | getb VR
 *     step T H                  fmi2DoStep
 *     steps N T0 H K VR1..VRK   N steps of H from T0, printing the K reals VR1..VRK after each
 *     save FILE                 fmi2GetFMUstate + fmi2SerializeFMUstate into FILE
 *     load FILE                 FILE's bytes through fmi2DeSerializeFMUstate + fmi2SetFMUstate
 *     load-corrupt              a state of 64 bytes of garbage through fmi2DeSerializeFMUstate
 *   The same through FMI 3.0 (the instance of the last inst3):
 *     inst3 NAME TOKEN PATH|-   fmi3InstantiateCoSimulation (logging on; '-' is NULL)
 *     enter3 T0 | exit3 | free3 fmi3EnterInitializationMode (the experiment from T0) ...
 *     setr3 VR VALUE | getr3 VR fmi3SetFloat64, fmi3GetFloat64
 *     steps3 N T0 H K VR1..VRK  N fmi3DoStep of H from T0, printing the K reals after each
 *     save3 FILE | load3 FILE   fmi3 state serialized into FILE, or FILE's bytes restored
 * Reals print alike through both standards, so a transcript's "real" lines compare.
 */
#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmi3Functions.h"

#ifdef _WIN32
#include <windows.h>
typedef HMODULE library_t;
static library_t open_library(const char *path) { return LoadLibraryA(path); }
static void *symbol(library_t lib, const char *name) { return (void *)GetProcAddress(lib, name); }
#else
#include <dlfcn.h>
typedef void *library_t;
static library_t open_library(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
static void *symbol(library_t lib, const char *name) { return dlsym(lib, name); }
#endif

static library_t lib;
#define F(name) ((name##TYPE *)need(#name))

static void *need(const char *name) {
    void *f = symbol(lib, name);
    if (f == NULL) {
        printf("missing %s\n", name);
        exit(2);
    }
    return f;
}

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    char text[4096];
    va_list args;
    (void)env;
    va_start(args, message);
    vsnprintf(text, sizeof text, message, args);
    va_end(args);
    printf("log %s %d %s: %s\n", instance ? instance : "(null)", (int)status,
           category ? category : "(null)", text);
}

static void *allocate(size_t n, size_t size) { return calloc(n, size); }

static const fmi2CallbackFunctions callbacks = {logger, allocate, free, NULL, NULL};

static void print_real(unsigned vr, double value) {
    uint64_t bits;
    memcpy(&bits, &value, sizeof bits);
    printf("real %u %016" PRIx64 "\n", vr, bits);
}

/* A status of either standard (their values agree: OK 0 ... Fatal 4). */
static void status(const char *what, int s) { printf("%s -> %d\n", what, s); }

/* FMI 3.0's log callback: the message itself, no format. */
static void logger3(fmi3InstanceEnvironment env, fmi3Status s, fmi3String category,
                    fmi3String message) {
    (void)env;
    printf("log %d %s: %s\n", (int)s, category ? category : "(null)", message ? message : "");
}

/* A file's bytes (malloc'ed; the caller frees them), or exit. */
static unsigned char *read_file(const char *file, size_t *size) {
    FILE *in = fopen(file, "rb");
    long length = -1;
    if (in != NULL && fseek(in, 0, SEEK_END) == 0) length = ftell(in);
    if (length < 0 || fseek(in, 0, SEEK_SET) != 0) {
        printf("cannot read %s\n", file);
        exit(2);
    }
    unsigned char *bytes = malloc((size_t)length + 1);
    *size = fread(bytes, 1, (size_t)length, in);
    fclose(in);
    return bytes;
}

static void write_file(const char *file, const void *bytes, size_t size) {
    FILE *out = fopen(file, "wb");
    if (out == NULL || fwrite(bytes, 1, size, out) != size) {
        printf("cannot write %s\n", file);
        exit(2);
    }
    fclose(out);
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: fmi_probe LIBRARY COMMAND...\n");
        return 2;
    }
    setvbuf(stdout, NULL, _IONBF, 0);
    lib = open_library(argv[1]);
    if (lib == NULL) {
        printf("cannot load %s\n", argv[1]);
        return 2;
    }
    fmi2Component c = NULL;
    int i = 2;
#define ARG() (i < argc ? argv[i++] : (fprintf(stderr, "missing argument\n"), exit(2), ""))
    while (i < argc) {
        const char *cmd = argv[i++];
        if (!strcmp(cmd, "inst")) {
            const char *name = ARG(), *guid = ARG(), *uri = ARG();
            c = F(fmi2Instantiate)(name, fmi2CoSimulation, guid, strcmp(uri, "-") ? uri : NULL,
                                   &callbacks, fmi2False, fmi2True);
            printf("instantiate -> %s\n", c ? "component" : "NULL");
        } else if (!strcmp(cmd, "inst-no-callbacks")) {
            const char *guid = ARG();
            fmi2Component none = F(fmi2Instantiate)("probe", fmi2CoSimulation, guid, NULL, NULL,
                                                    fmi2False, fmi2True);
            printf("instantiate -> %s\n", none ? "component" : "NULL");
        } else if (!strcmp(cmd, "setup")) {
            double t0 = strtod(ARG(), NULL);
            status("setup", F(fmi2SetupExperiment)(c, fmi2False, 0.0, t0, fmi2False, 0.0));
        } else if (!strcmp(cmd, "enter")) {
            status("enter", F(fmi2EnterInitializationMode)(c));
        } else if (!strcmp(cmd, "exit")) {
            status("exit", F(fmi2ExitInitializationMode)(c));
        } else if (!strcmp(cmd, "terminate")) {
            status("terminate", F(fmi2Terminate)(c));
        } else if (!strcmp(cmd, "reset")) {
            status("reset", F(fmi2Reset)(c));
        } else if (!strcmp(cmd, "free")) {
            F(fmi2FreeInstance)(c);
            c = NULL;
            printf("freed\n");
        } else if (!strcmp(cmd, "setr")) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(ARG(), NULL, 10);
            fmi2Real v = strtod(ARG(), NULL);
            status("setr", F(fmi2SetReal)(c, &vr, 1, &v));
        } else if (!strcmp(cmd, "seti")) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(ARG(), NULL, 10);
            fmi2Integer v = (fmi2Integer)strtol(ARG(), NULL, 10);
            status("seti", F(fmi2SetInteger)(c, &vr, 1, &v));
        } else if (!strcmp(cmd, "setb")) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(ARG(), NULL, 10);
            fmi2Boolean v = (fmi2Boolean)strtol(ARG(), NULL, 10);
            status("setb", F(fmi2SetBoolean)(c, &vr, 1, &v));
        } else if (!strcmp(cmd, "sets")) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(ARG(), NULL, 10);
            fmi2String v = ARG();
            status("sets", F(fmi2SetString)(c, &vr, 1, &v));
        } else if (!strcmp(cmd, "getr")) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(ARG(), NULL, 10);
            fmi2Real v = 0;
            status("getr", F(fmi2GetReal)(c, &vr, 1, &v));
            print_real(vr, v);
        } else if (!strcmp(cmd, "geti")) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(ARG(), NULL, 10);
            fmi2Integer v = 0;
            status("geti", F(fmi2GetInteger)(c, &vr, 1, &v));
            printf("integer %u %d\n", vr, (int)v);
        } else if (!strcmp(cmd, "getb")) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(ARG(), NULL, 10);
            fmi2Boolean v = 0;
            status("getb", F(fmi2GetBoolean)(c, &vr, 1, &v));
            printf("boolean %u %d\n", vr, (int)v);
        } else if (!strcmp(cmd, "step")) {
            double t = strtod(ARG(), NULL), h = strtod(ARG(), NULL);
            status("step", F(fmi2DoStep)(c, t, h, fmi2True));
        } else if (!strcmp(cmd, "steps")) {
            long n = strtol(ARG(), NULL, 10);
            double t0 = strtod(ARG(), NULL), h = strtod(ARG(), NULL);
            int count = (int)strtol(ARG(), NULL, 10), first = i;
            if (count < 0 || first + count > argc) {
                fprintf(stderr, "steps: fewer value references than %d\n", count);
                return 2;
            }
            i += count;
            for (long k = 0; k < n; k++) {
                fmi2Status s = F(fmi2DoStep)(c, t0 + (double)k * h, h, fmi2True);
                if (s != fmi2OK) {
                    printf("step %ld -> %d\n", k, (int)s);
                    break;
                }
                for (int j = first; j < first + count; j++) {
                    fmi2ValueReference vr = (fmi2ValueReference)strtoul(argv[j], NULL, 10);
                    fmi2Real v = 0;
                    if (F(fmi2GetReal)(c, &vr, 1, &v) != fmi2OK) printf("getr %u failed\n", vr);
                    print_real(vr, v);
                }
            }
        } else if (!strcmp(cmd, "save")) {
            const char *file = ARG();
            fmi2FMUstate state = NULL;
            size_t size = 0;
            status("get state", F(fmi2GetFMUstate)(c, &state));
            status("state size", F(fmi2SerializedFMUstateSize)(c, state, &size));
            fmi2Byte *bytes = malloc(size ? size : 1);
            status("serialize", F(fmi2SerializeFMUstate)(c, state, bytes, size));
            write_file(file, bytes, size);
            free(bytes);
            status("free state", F(fmi2FreeFMUstate)(c, &state));
        } else if (!strcmp(cmd, "load") || !strcmp(cmd, "load-corrupt")) {
            size_t size = 64;
            fmi2Byte *bytes = NULL;
            if (!strcmp(cmd, "load")) {
                bytes = (fmi2Byte *)read_file(ARG(), &size);
            } else {
                bytes = malloc(size);
                for (size_t k = 0; k < size; k++) bytes[k] = (fmi2Byte)(k * 37 + 11);
            }
            fmi2FMUstate state = NULL;
            fmi2Status s = F(fmi2DeSerializeFMUstate)(c, bytes, size, &state);
            status("deserialize", s);
            if (s == fmi2OK) {
                status("set state", F(fmi2SetFMUstate)(c, state));
                status("free state", F(fmi2FreeFMUstate)(c, &state));
            }
            free(bytes);
        } else if (!strcmp(cmd, "inst3")) {
            const char *name = ARG(), *token = ARG(), *path = ARG();
            c = F(fmi3InstantiateCoSimulation)(name, token, strcmp(path, "-") ? path : NULL,
                                               false, true, false, false, NULL, 0, NULL,
                                               logger3, NULL);
            printf("instantiate -> %s\n", c ? "component" : "NULL");
        } else if (!strcmp(cmd, "enter3")) {
            double t0 = strtod(ARG(), NULL);
            status("enter", F(fmi3EnterInitializationMode)(c, false, 0.0, t0, false, 0.0));
        } else if (!strcmp(cmd, "exit3")) {
            status("exit", F(fmi3ExitInitializationMode)(c));
        } else if (!strcmp(cmd, "free3")) {
            F(fmi3FreeInstance)(c);
            c = NULL;
            printf("freed\n");
        } else if (!strcmp(cmd, "setr3")) {
            fmi3ValueReference vr = (fmi3ValueReference)strtoul(ARG(), NULL, 10);
            fmi3Float64 v = strtod(ARG(), NULL);
            status("setr", F(fmi3SetFloat64)(c, &vr, 1, &v, 1));
        } else if (!strcmp(cmd, "getr3")) {
            fmi3ValueReference vr = (fmi3ValueReference)strtoul(ARG(), NULL, 10);
            fmi3Float64 v = 0;
            status("getr", F(fmi3GetFloat64)(c, &vr, 1, &v, 1));
            print_real(vr, v);
        } else if (!strcmp(cmd, "steps3")) {
            long n = strtol(ARG(), NULL, 10);
            double t0 = strtod(ARG(), NULL), h = strtod(ARG(), NULL);
            int count = (int)strtol(ARG(), NULL, 10), first = i;
            if (count < 0 || first + count > argc) {
                fprintf(stderr, "steps3: fewer value references than %d\n", count);
                return 2;
            }
            i += count;
            for (long k = 0; k < n; k++) {
                bool event = true, terminate = true, early = true;
                double last = -1.0;
                fmi3Status s = F(fmi3DoStep)(c, t0 + (double)k * h, h, true, &event, &terminate,
                                             &early, &last);
                if (s != fmi3OK || event || terminate || early) {
                    printf("step %ld -> %d (%d %d %d)\n", k, (int)s, event, terminate, early);
                    break;
                }
                for (int j = first; j < first + count; j++) {
                    fmi3ValueReference vr = (fmi3ValueReference)strtoul(argv[j], NULL, 10);
                    fmi3Float64 v = 0;
                    if (F(fmi3GetFloat64)(c, &vr, 1, &v, 1) != fmi3OK) printf("getr %u failed\n", vr);
                    print_real(vr, v);
                }
            }
        } else if (!strcmp(cmd, "save3")) {
            const char *file = ARG();
            fmi3FMUState state = NULL;
            size_t size = 0;
            status("get state", F(fmi3GetFMUState)(c, &state));
            status("state size", F(fmi3SerializedFMUStateSize)(c, state, &size));
            fmi3Byte *bytes = malloc(size ? size : 1);
            status("serialize", F(fmi3SerializeFMUState)(c, state, bytes, size));
            write_file(file, bytes, size);
            free(bytes);
            status("free state", F(fmi3FreeFMUState)(c, &state));
        } else if (!strcmp(cmd, "load3")) {
            size_t size = 0;
            fmi3Byte *bytes = read_file(ARG(), &size);
            fmi3FMUState state = NULL;
            fmi3Status s = F(fmi3DeserializeFMUState)(c, bytes, size, &state);
            status("deserialize", s);
            if (s == fmi3OK) {
                status("set state", F(fmi3SetFMUState)(c, state));
                status("free state", F(fmi3FreeFMUState)(c, &state));
            }
            free(bytes);
        } else {
            fprintf(stderr, "unknown command %s\n", cmd);
            return 2;
        }
    }
    return 0;
}
