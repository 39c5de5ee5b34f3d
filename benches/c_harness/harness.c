/* The C harness of issue 21: what one sample costs an importer written in C.
 *
 *   harness [--samples N] [--passes P] [--warmup W] [--json FILE] [--only LABEL]
 *           [--dump FILE] [--set LABEL:NAME=VALUE ...] LABEL=LIBRARY:MODEL_DESCRIPTION ...
 *
 * Each model is dlopen'ed from LIBRARY (an FMU's binaries/linux64/<id>.so), its GUID,
 * model identifier and Real inputs and outputs read from MODEL_DESCRIPTION (the FMU's
 * modelDescription.xml), and one instance started: fmi2Instantiate (logging off),
 * fmi2SetupExperiment(0, no stop time), fmi2EnterInitializationMode,
 * fmi2ExitInitializationMode. One sample is then what a co-simulation master pays per
 * communication step of 1 ms: fmi2SetReal of all Real inputs, fmi2DoStep, fmi2GetReal of
 * all Real outputs. The inputs follow a lagging circle: the reference ref = R(cos θ,
 * sin θ), θ = 2π f t, the measured position pos 20 ms behind it and 50 µm inside, the
 * velocity command u the derivative of pos (R = 10 mm, f = 0.5 Hz; the N samples of a
 * pass are whole periods, so passes continue the same circle). Inputs are matched by
 * name: ref.x/ref.y, pos.x/pos.y, u.x/u.y; in1..in4 (the bare pass-through) take ref.x,
 * ref.y, pos.x, pos.y; any other Real input is held at 0.
 *
 * Two loops are timed, on the same instance:
 * - calls_only: the inputs of the N samples are computed before timing, so the timed loop
 *   is the three calls and nothing else: the FMU's own cost, the bare pass-through's
 *   being the floor of three calls through dlopen'ed pointers;
 * - importer_loop: the importer computes each sample's inputs on the circle (sin and cos
 *   of the reference's and of the lagging position's angle) just before the calls, as a
 *   master generating its inputs does: what a sample costs the importer in all.
 *
 * Passes alternate between the models (pass p starts with model p mod M) and between the
 * loops (calls_only first in even passes), each timing N samples with CLOCK_MONOTONIC,
 * after W untimed warm-up passes: a burst of load from another process hits neighbouring
 * passes of all models alike. Reported per model and loop: the median and minimum ns per
 * sample over the P passes; per model after the first (the baseline, the bare C
 * pass-through): the median over passes of its time / the baseline's time in the same
 * pass. With --json, the same as JSON.
 *
 * --only LABEL runs that model's passes alone, for valgrind --tool=callgrind
 * --toggle-collect=run_calls_only: instructions / (N * (W + P)) is then the instruction
 * count of one sample's calls (benches/c_harness/run.sh --callgrind).
 *
 * --set LABEL:NAME=VALUE sets the Integer, Enumeration or String parameter NAME of model
 * LABEL before initialization (ContourCCC2D's estimator and path: the program estimator
 * beside the free-curve one; benches/ccc_sample_cost.py).
 *
 * --dump FILE writes every output of every calls_only sample (doubles, in the machine's
 * byte order): two builds of a library compute the same outputs if their dumps are equal
 * byte for byte (run with --only LABEL and the same N, P and W).
 *
 * Built by benches/c_harness/run.sh with gcc -O2; `make bench` runs it.
 */

#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmi2Functions.h"

#define MAX_MODELS 16
enum loop { CALLS_ONLY, IMPORTER_LOOP, LOOPS };
static const char *const LOOP_NAME[LOOPS] = {"calls_only", "importer_loop"};
/* What an input is fed: the lagging circle's coordinates, or 0. */
enum signal { REF_X, REF_Y, POS_X, POS_Y, U_X, U_Y, ZERO, SIGNALS };
#define MAX_VARS 256
#define H 1e-3
#define RADIUS 10.0
#define FREQUENCY 0.5
#define LAG 0.020
#define INSIDE 0.050
#define PI 3.14159265358979323846

#define MAX_SETTINGS 8

typedef struct {
    const char *label;
    const char *library;
    const char *description_path;
    char identifier[256];
    char guid[256];
    fmi2InstantiateTYPE *instantiate;
    fmi2FreeInstanceTYPE *free_instance;
    fmi2SetupExperimentTYPE *setup_experiment;
    fmi2EnterInitializationModeTYPE *enter_initialization;
    fmi2ExitInitializationModeTYPE *exit_initialization;
    fmi2SetRealTYPE *set_real;
    fmi2GetRealTYPE *get_real;
    fmi2DoStepTYPE *do_step;
    fmi2SetIntegerTYPE *set_integer;
    fmi2SetStringTYPE *set_string;
    const char *setting[MAX_SETTINGS]; /* NAME=VALUE */
    size_t n_settings;
    fmi2Component c;
    fmi2ValueReference in_vr[MAX_VARS];
    enum signal in_signal[MAX_VARS];
    size_t n_in;
    fmi2ValueReference out_vr[MAX_VARS];
    size_t n_out;
    double *rows;  /* samples x n_in input values (calls_only) */
    double in[MAX_VARS];  /* one sample's inputs (importer_loop) */
    double out[MAX_VARS];
    unsigned long long step; /* communication steps taken */
    double *ns[LOOPS];  /* per pass */
    double checksum;
} Model;

static void die(const char *format, ...) {
    va_list args;
    va_start(args, format);
    fputs("harness: ", stderr);
    vfprintf(stderr, format, args);
    fputc('\n', stderr);
    va_end(args);
    exit(1);
}

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    (void)env;
    if (status < fmi2Warning) return;
    va_list args;
    va_start(args, message);
    fprintf(stderr, "[%s %s] ", instance ? instance : "?", category ? category : "?");
    vfprintf(stderr, message, args);
    fputc('\n', stderr);
    va_end(args);
}

static char *read_file(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f) die("cannot open %s", path);
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *text = malloc((size_t)size + 1);
    if (!text || fread(text, 1, (size_t)size, f) != (size_t)size) die("cannot read %s", path);
    text[size] = 0;
    fclose(f);
    return text;
}

/* The value of attribute `name` within [start, end), copied to out; 0 if absent. */
static int attribute(const char *start, const char *end, const char *name, char *out,
                     size_t size) {
    size_t n = strlen(name);
    for (const char *p = start; p && p < end; p++) {
        p = strstr(p, name);
        if (!p || p >= end) return 0;
        if ((p == start || p[-1] == ' ' || p[-1] == '\n' || p[-1] == '\t') && p[n] == '=' &&
            p[n + 1] == '"') {
            const char *value = p + n + 2, *close = strchr(value, '"');
            if (!close || close >= end || (size_t)(close - value) >= size) return 0;
            memcpy(out, value, (size_t)(close - value));
            out[close - value] = 0;
            return 1;
        }
    }
    return 0;
}

/* The signal an input named `name` is fed. */
static enum signal signal_of(const char *name) {
    static const char *const names[ZERO] = {"ref.x", "ref.y", "pos.x", "pos.y", "u.x", "u.y"};
    if (name[0] == 'i' && name[1] == 'n' && name[2] >= '1' && name[2] <= '4' && !name[3])
        return (enum signal)(name[2] - '1'); /* in1..in4: ref.x, ref.y, pos.x, pos.y */
    for (int i = 0; i < ZERO; i++)
        if (!strcmp(name, names[i])) return (enum signal)i;
    return ZERO;
}

/* The lagging circle at time t: every signal's value. */
static inline void circle(double t, double value[SIGNALS]) {
    const double w = 2.0 * PI * FREQUENCY, r = RADIUS - INSIDE;
    double ref = w * t, lagged = w * (t - LAG);
    double c = cos(lagged), s = sin(lagged);
    value[REF_X] = RADIUS * cos(ref);
    value[REF_Y] = RADIUS * sin(ref);
    value[POS_X] = r * c;
    value[POS_Y] = r * s;
    value[U_X] = -r * w * s;
    value[U_Y] = r * w * c;
    value[ZERO] = 0.0;
}

/* The value reference and type element ("Integer", "Enumeration", "String", ...) of the
   variable called `name` in a modelDescription.xml; dies if there is none. */
static fmi2ValueReference variable(const char *path, const char *wanted, char *type,
                                   size_t size) {
    char *xml = read_file(path);
    for (const char *v = strstr(xml, "<ScalarVariable"); v; v = strstr(v + 1, "<ScalarVariable")) {
        const char *head_end = strchr(v, '>');
        char name[256], vr[32];
        if (!head_end || !attribute(v, head_end, "name", name, sizeof name) || strcmp(name, wanted))
            continue;
        if (!attribute(v, head_end, "valueReference", vr, sizeof vr)) break;
        const char *element = head_end + 1;
        while (*element && *element != '<') element++;
        size_t n = strcspn(element + 1, " />\n\t");
        if (!*element || n >= size) break;
        memcpy(type, element + 1, n);
        type[n] = 0;
        free(xml);
        return (fmi2ValueReference)strtoul(vr, NULL, 10);
    }
    die("%s: no variable %s", path, wanted);
    return 0;
}

/* Applies the model's --set NAME=VALUE settings (before initialization). */
static void apply_settings(Model *m) {
    for (size_t i = 0; i < m->n_settings; i++) {
        char name[256], type[32];
        const char *eq = strchr(m->setting[i], '=');
        if (!eq || (size_t)(eq - m->setting[i]) >= sizeof name) die("bad --set %s", m->setting[i]);
        memcpy(name, m->setting[i], (size_t)(eq - m->setting[i]));
        name[eq - m->setting[i]] = 0;
        fmi2ValueReference vr = variable(m->description_path, name, type, sizeof type);
        fmi2Status status;
        if (!strcmp(type, "String")) {
            fmi2String value = eq + 1;
            status = m->set_string(m->c, &vr, 1, &value);
        } else if (!strcmp(type, "Integer") || !strcmp(type, "Enumeration")) {
            fmi2Integer value = (fmi2Integer)strtol(eq + 1, NULL, 10);
            status = m->set_integer(m->c, &vr, 1, &value);
        } else {
            die("%s: --set takes Integer, Enumeration or String variables, not %s", name, type);
        }
        if (status != fmi2OK) die("%s: setting %s failed", m->label, m->setting[i]);
    }
}

/* GUID, model identifier and the Real inputs and outputs of a modelDescription.xml. */
static void read_description(Model *m) {
    char *xml = read_file(m->description_path);
    const char *root = strstr(xml, "<fmiModelDescription");
    const char *cs = strstr(xml, "<CoSimulation");
    if (!root || !cs) die("%s: no fmiModelDescription/CoSimulation", m->description_path);
    if (!attribute(root, cs, "guid", m->guid, sizeof m->guid))
        die("%s: no guid", m->description_path);
    if (!attribute(cs, strchr(cs, '>'), "modelIdentifier", m->identifier, sizeof m->identifier))
        die("%s: no modelIdentifier", m->description_path);
    for (const char *v = strstr(xml, "<ScalarVariable"); v; v = strstr(v + 1, "<ScalarVariable")) {
        const char *head_end = strchr(v, '>');
        const char *end = strstr(v, "</ScalarVariable>");
        if (!head_end) break;
        if (head_end[-1] == '/' || !end) end = head_end; /* no type element */
        char name[256], vr[32], causality[32];
        if (!attribute(v, head_end, "name", name, sizeof name) ||
            !attribute(v, head_end, "valueReference", vr, sizeof vr))
            die("%s: a ScalarVariable without name or valueReference", m->description_path);
        if (!attribute(v, head_end, "causality", causality, sizeof causality))
            strcpy(causality, "local");
        const char *real = strstr(head_end, "<Real");
        if (!real || real > end) continue;
        if (strcmp(causality, "input") == 0) {
            if (m->n_in == MAX_VARS) die("too many inputs");
            m->in_signal[m->n_in] = signal_of(name);
            m->in_vr[m->n_in++] = (fmi2ValueReference)strtoul(vr, NULL, 10);
        } else if (strcmp(causality, "output") == 0) {
            if (m->n_out == MAX_VARS) die("too many outputs");
            m->out_vr[m->n_out++] = (fmi2ValueReference)strtoul(vr, NULL, 10);
        }
    }
    free(xml);
}

static void *symbol(void *library, const char *path, const char *name) {
    void *f = dlsym(library, name);
    if (!f) die("%s: no %s", path, name);
    return f;
}

static FILE *dump;

static const fmi2CallbackFunctions CALLBACKS = {logger, calloc, free, NULL, NULL};

static void start(Model *m) {
    read_description(m);
    void *library = dlopen(m->library, RTLD_NOW | RTLD_LOCAL);
    if (!library) die("cannot load %s: %s", m->library, dlerror());
    m->instantiate = (fmi2InstantiateTYPE *)symbol(library, m->library, "fmi2Instantiate");
    m->free_instance = (fmi2FreeInstanceTYPE *)symbol(library, m->library, "fmi2FreeInstance");
    m->setup_experiment =
        (fmi2SetupExperimentTYPE *)symbol(library, m->library, "fmi2SetupExperiment");
    m->enter_initialization = (fmi2EnterInitializationModeTYPE *)symbol(
        library, m->library, "fmi2EnterInitializationMode");
    m->exit_initialization = (fmi2ExitInitializationModeTYPE *)symbol(
        library, m->library, "fmi2ExitInitializationMode");
    m->set_real = (fmi2SetRealTYPE *)symbol(library, m->library, "fmi2SetReal");
    m->get_real = (fmi2GetRealTYPE *)symbol(library, m->library, "fmi2GetReal");
    m->do_step = (fmi2DoStepTYPE *)symbol(library, m->library, "fmi2DoStep");
    if (m->n_settings) {
        m->set_integer = (fmi2SetIntegerTYPE *)symbol(library, m->library, "fmi2SetInteger");
        m->set_string = (fmi2SetStringTYPE *)symbol(library, m->library, "fmi2SetString");
    }
    m->c = m->instantiate(m->label, fmi2CoSimulation, m->guid, NULL, &CALLBACKS, fmi2False,
                          fmi2False);
    if (!m->c) die("%s: fmi2Instantiate(%s, %s) failed", m->label, m->identifier, m->guid);
    apply_settings(m);
    if (m->setup_experiment(m->c, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK ||
        m->enter_initialization(m->c) != fmi2OK || m->exit_initialization(m->c) != fmi2OK)
        die("%s: initialization failed", m->label);
}

static double now_ns(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

/* N samples on one model with the inputs computed before (callgrind's --toggle-collect
   target). */
__attribute__((noinline)) void run_calls_only(Model *m, size_t samples) {
    fmi2Component c = m->c;
    for (size_t k = 0; k < samples; k++) {
        double t = (double)m->step * H;
        fmi2Status status = m->set_real(c, m->in_vr, m->n_in, m->rows + k * m->n_in);
        status |= m->do_step(c, t, H, fmi2True);
        status |= m->get_real(c, m->out_vr, m->n_out, m->out);
        if (status != fmi2OK) die("%s: a call failed at t = %g", m->label, t);
        if (dump && fwrite(m->out, sizeof *m->out, m->n_out, dump) != m->n_out) die("dump failed");
        m->step++;
    }
    m->checksum += m->n_out ? m->out[0] : 0.0;
}

/* N samples on one model, each computing its inputs on the circle first. */
__attribute__((noinline)) void run_importer_loop(Model *m, size_t samples) {
    fmi2Component c = m->c;
    double value[SIGNALS];
    for (size_t k = 0; k < samples; k++) {
        double t = (double)m->step * H;
        circle(t, value);
        for (size_t j = 0; j < m->n_in; j++) m->in[j] = value[m->in_signal[j]];
        fmi2Status status = m->set_real(c, m->in_vr, m->n_in, m->in);
        status |= m->do_step(c, t, H, fmi2True);
        status |= m->get_real(c, m->out_vr, m->n_out, m->out);
        if (status != fmi2OK) die("%s: a call failed at t = %g", m->label, t);
        m->step++;
    }
    m->checksum += m->n_out ? m->out[0] : 0.0;
}

static int compare(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(const double *values, size_t n) {
    double *sorted = malloc(n * sizeof *sorted);
    memcpy(sorted, values, n * sizeof *sorted);
    qsort(sorted, n, sizeof *sorted, compare);
    double mid = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
    free(sorted);
    return mid;
}

static double minimum(const double *values, size_t n) {
    double low = values[0];
    for (size_t i = 1; i < n; i++) low = values[i] < low ? values[i] : low;
    return low;
}

static void json_string(FILE *f, const char *s) {
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"' || *s == '\\') fputc('\\', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

int main(int argc, char **argv) {
    size_t samples = 4000, passes = 101, warmup = 3;
    const char *json = NULL, *only = NULL;
    Model models[MAX_MODELS];
    size_t n = 0;
    const char *settings[MAX_MODELS * MAX_SETTINGS];
    size_t n_settings = 0;
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (!strcmp(arg, "--samples") && i + 1 < argc) samples = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(arg, "--passes") && i + 1 < argc) passes = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(arg, "--warmup") && i + 1 < argc) warmup = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(arg, "--json") && i + 1 < argc) json = argv[++i];
        else if (!strcmp(arg, "--only") && i + 1 < argc) only = argv[++i];
        else if (!strcmp(arg, "--set") && i + 1 < argc) {
            if (n_settings == MAX_MODELS * MAX_SETTINGS) die("too many --set");
            settings[n_settings++] = argv[++i];
        }
        else if (!strcmp(arg, "--dump") && i + 1 < argc) {
            if (!(dump = fopen(argv[++i], "wb"))) die("cannot write %s", argv[i]);
        }
        else if (arg[0] == '-') die("unknown option %s", arg);
        else {
            char *spec = strdup(arg), *eq = strchr(spec, '='), *colon = eq ? strchr(eq, ':') : NULL;
            if (!eq || !colon) die("expected LABEL=LIBRARY:MODEL_DESCRIPTION, got %s", arg);
            if (n == MAX_MODELS) die("at most %d models", MAX_MODELS);
            *eq = *colon = 0;
            memset(&models[n], 0, sizeof models[n]);
            models[n].label = spec;
            models[n].library = eq + 1;
            models[n].description_path = colon + 1;
            n++;
        }
    }
    if (!n || !samples || !passes)
        die("usage: harness [--samples N] [--passes P] [--warmup W] [--json FILE] "
            "[--only LABEL] [--dump FILE] [--set LABEL:NAME=VALUE ...] LABEL=LIB:XML ...");
    for (size_t k = 0; k < n_settings; k++) {
        const char *colon = strchr(settings[k], ':');
        size_t found = n;
        for (size_t i = 0; colon && i < n; i++)
            if (strlen(models[i].label) == (size_t)(colon - settings[k]) &&
                !strncmp(models[i].label, settings[k], (size_t)(colon - settings[k])))
                found = i;
        if (found == n) die("--set %s: expected LABEL:NAME=VALUE for a model given", settings[k]);
        if (models[found].n_settings == MAX_SETTINGS) die("too many --set for %s", models[found].label);
        models[found].setting[models[found].n_settings++] = colon + 1;
    }
    if (only) {
        size_t kept = 0;
        for (size_t i = 0; i < n; i++)
            if (!strcmp(models[i].label, only)) models[kept++] = models[i];
        if (!kept) die("no model labelled %s", only);
        n = kept;
    }
    for (size_t i = 0; i < n; i++) {
        Model *m = &models[i];
        start(m);
        m->rows = malloc(samples * (m->n_in ? m->n_in : 1) * sizeof *m->rows);
        for (int l = 0; l < LOOPS; l++) m->ns[l] = calloc(passes, sizeof *m->ns[l]);
        for (size_t k = 0; k < samples; k++) {
            double value[SIGNALS];
            circle((double)k * H, value);
            for (size_t j = 0; j < m->n_in; j++) m->rows[k * m->n_in + j] = value[m->in_signal[j]];
        }
        fprintf(stderr, "%-14s %s (%s): %zu Real inputs, %zu Real outputs\n", m->label,
                m->identifier, m->library, m->n_in, m->n_out);
    }
    for (size_t p = 0; p < warmup + passes; p++) {
        for (size_t j = 0; j < n; j++) {
            Model *m = &models[(p + j) % n];
            for (int i = 0; i < LOOPS; i++) {
                int l = p % 2 ? LOOPS - 1 - i : i;
                double t0 = now_ns();
                if (l == CALLS_ONLY) run_calls_only(m, samples);
                else run_importer_loop(m, samples);
                double elapsed = now_ns() - t0;
                if (p >= warmup) m->ns[l][p - warmup] = elapsed / (double)samples;
            }
        }
    }
    double *ratios = calloc(passes, sizeof *ratios), ratio[LOOPS][MAX_MODELS] = {{0}};
    for (int l = 0; l < LOOPS; l++)
        for (size_t i = 1; i < n; i++) {
            for (size_t p = 0; p < passes; p++) ratios[p] = models[i].ns[l][p] / models[0].ns[l][p];
            ratio[l][i] = median(ratios, passes);
        }
    printf("ns per sample (fmi2SetReal all Real inputs + fmi2DoStep + fmi2GetReal all Real "
           "outputs), median (min) of %zu passes of %zu samples\n",
           passes, samples);
    int width = 14;
    for (size_t i = 0; i < n; i++)
        width = (int)strlen(models[i].label) > width ? (int)strlen(models[i].label) : width;
    printf("  %-*s %-30s %s\n", width, "", "calls only", "importer loop (inputs computed)");
    for (size_t i = 0; i < n; i++) {
        Model *m = &models[i];
        printf("  %-*s", width, m->label);
        for (int l = 0; l < LOOPS; l++) {
            char text[64];
            int len = snprintf(text, sizeof text, "%.1f ns (%.1f)", median(m->ns[l], passes),
                               minimum(m->ns[l], passes));
            if (i) snprintf(text + len, sizeof text - (size_t)len, "  %.2fx", ratio[l][i]);
            printf(" %-30s", text);
        }
        printf("\n");
    }
    if (json) {
        FILE *f = fopen(json, "w");
        if (!f) die("cannot write %s", json);
        fprintf(f, "{\n  \"samples_per_pass\": %zu,\n  \"passes\": %zu,\n  \"step_s\": %g,\n",
                samples, passes, H);
        fprintf(f, "  \"baseline\": ");
        json_string(f, models[0].label);
        fprintf(f, ",\n  \"models\": {\n");
        for (size_t i = 0; i < n; i++) {
            Model *m = &models[i];
            fprintf(f, "    ");
            json_string(f, m->label);
            fprintf(f, ": {\"identifier\": ");
            json_string(f, m->identifier);
            fprintf(f, ", \"library\": ");
            json_string(f, m->library);
            fprintf(f, ", \"real_inputs\": %zu, \"real_outputs\": %zu", m->n_in, m->n_out);
            for (int l = 0; l < LOOPS; l++) {
                fprintf(f, ",\n      \"%s\": {\"median_ns_per_sample\": %.2f, "
                           "\"min_ns_per_sample\": %.2f, \"ns_per_sample\": [",
                        LOOP_NAME[l], median(m->ns[l], passes), minimum(m->ns[l], passes));
                for (size_t p = 0; p < passes; p++) fprintf(f, "%s%.2f", p ? ", " : "", m->ns[l][p]);
                fprintf(f, "]}");
            }
            fprintf(f, "}%s\n", i + 1 < n ? "," : "");
        }
        fprintf(f, "  },\n  \"ratios_over_baseline\": {");
        for (int l = 0; l < LOOPS; l++) {
            fprintf(f, "%s\n    \"%s\": {", l ? "," : "", LOOP_NAME[l]);
            for (size_t i = 1; i < n; i++) {
                fprintf(f, "%s", i > 1 ? ", " : "");
                json_string(f, models[i].label);
                fprintf(f, ": %.4f", ratio[l][i]);
            }
            fprintf(f, "}");
        }
        fprintf(f, "\n  }\n}\n");
        fclose(f);
    }
    double checksum = 0;
    for (size_t i = 0; i < n; i++) checksum += models[i].checksum;
    if (!isfinite(checksum)) die("non-finite outputs");
    for (size_t i = 0; i < n; i++) models[i].free_instance(models[i].c);
    if (dump && fclose(dump) != 0) die("dump failed");
    return 0;
}
