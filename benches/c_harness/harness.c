/* The C harness of issue 21: what one sample costs an importer written in C.
 *
 *   harness [--samples N] [--passes P] [--warmup W] [--json FILE] [--only LABEL]
 *           LABEL=LIBRARY:MODEL_DESCRIPTION ...
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
 * ref.y, pos.x, pos.y; any other Real input is held at 0. The rows are computed before
 * timing, so the timed loop is the three calls and nothing else.
 *
 * Passes alternate between the models (pass p starts with model p mod M), each timing N
 * samples with CLOCK_MONOTONIC, after W untimed warm-up passes: a burst of load from
 * another process hits neighbouring passes of all models alike. Reported per model: the
 * median and minimum ns per sample over the P passes; per model after the first (the
 * baseline, the bare C pass-through): the median over passes of its time / the
 * baseline's time in the same pass. With --json, the same as JSON.
 *
 * --only LABEL runs that model's passes alone, for valgrind --tool=callgrind
 * --toggle-collect=run_pass: instructions / (N * P) is then the instruction count of one
 * sample (benches/c_harness/run.sh --callgrind).
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

#define MAX_MODELS 8
#define MAX_VARS 256
#define H 1e-3
#define RADIUS 10.0
#define FREQUENCY 0.5
#define LAG 0.020
#define INSIDE 0.050
#define PI 3.14159265358979323846

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
    fmi2Component c;
    fmi2ValueReference in_vr[MAX_VARS];
    char *in_name[MAX_VARS];
    size_t n_in;
    fmi2ValueReference out_vr[MAX_VARS];
    size_t n_out;
    double *rows;  /* samples x n_in input values */
    double out[MAX_VARS];
    unsigned long long step; /* communication steps taken */
    double *ns;  /* per pass */
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
            m->in_name[m->n_in] = strdup(name);
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
    m->c = m->instantiate(m->label, fmi2CoSimulation, m->guid, NULL, &CALLBACKS, fmi2False,
                          fmi2False);
    if (!m->c) die("%s: fmi2Instantiate(%s, %s) failed", m->label, m->identifier, m->guid);
    if (m->setup_experiment(m->c, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK ||
        m->enter_initialization(m->c) != fmi2OK || m->exit_initialization(m->c) != fmi2OK)
        die("%s: initialization failed", m->label);
}

/* The lagging circle's value of input `name` at sample k. */
static double signal(const char *name, size_t k) {
    double t = (double)k * H, w = 2.0 * PI * FREQUENCY;
    double ref = w * t, lagged = w * (t - LAG), r = RADIUS - INSIDE;
    static const char *const numbered[] = {"ref.x", "ref.y", "pos.x", "pos.y"};
    if (name[0] == 'i' && name[1] == 'n' && name[2] >= '1' && name[2] <= '4' && !name[3])
        name = numbered[name[2] - '1'];
    if (!strcmp(name, "ref.x")) return RADIUS * cos(ref);
    if (!strcmp(name, "ref.y")) return RADIUS * sin(ref);
    if (!strcmp(name, "pos.x")) return r * cos(lagged);
    if (!strcmp(name, "pos.y")) return r * sin(lagged);
    if (!strcmp(name, "u.x")) return -r * w * sin(lagged);
    if (!strcmp(name, "u.y")) return r * w * cos(lagged);
    return 0.0;
}

static double now_ns(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

/* N samples on one model: the timed loop (and callgrind's --toggle-collect target). */
__attribute__((noinline)) void run_pass(Model *m, size_t samples) {
    fmi2Component c = m->c;
    for (size_t k = 0; k < samples; k++) {
        double t = (double)m->step * H;
        fmi2Status status = m->set_real(c, m->in_vr, m->n_in, m->rows + k * m->n_in);
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
    size_t samples = 4000, passes = 51, warmup = 3;
    const char *json = NULL, *only = NULL;
    Model models[MAX_MODELS];
    size_t n = 0;
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (!strcmp(arg, "--samples") && i + 1 < argc) samples = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(arg, "--passes") && i + 1 < argc) passes = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(arg, "--warmup") && i + 1 < argc) warmup = strtoul(argv[++i], NULL, 10);
        else if (!strcmp(arg, "--json") && i + 1 < argc) json = argv[++i];
        else if (!strcmp(arg, "--only") && i + 1 < argc) only = argv[++i];
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
    if (!n || !samples || !passes) die("usage: harness [--samples N] [--passes P] [--warmup W] "
                                       "[--json FILE] [--only LABEL] LABEL=LIB:XML ...");
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
        m->ns = calloc(passes, sizeof *m->ns);
        for (size_t k = 0; k < samples; k++)
            for (size_t j = 0; j < m->n_in; j++) m->rows[k * m->n_in + j] = signal(m->in_name[j], k);
        fprintf(stderr, "%-14s %s (%s): %zu Real inputs, %zu Real outputs\n", m->label,
                m->identifier, m->library, m->n_in, m->n_out);
    }
    for (size_t p = 0; p < warmup + passes; p++) {
        for (size_t j = 0; j < n; j++) {
            Model *m = &models[(p + j) % n];
            double t0 = now_ns();
            run_pass(m, samples);
            double elapsed = now_ns() - t0;
            if (p >= warmup) m->ns[p - warmup] = elapsed / (double)samples;
        }
    }
    double *ratios = calloc(passes, sizeof *ratios), ratio[MAX_MODELS] = {0};
    for (size_t i = 1; i < n; i++) {
        for (size_t p = 0; p < passes; p++) ratios[p] = models[i].ns[p] / models[0].ns[p];
        ratio[i] = median(ratios, passes);
    }
    printf("ns per sample (fmi2SetReal all Real inputs + fmi2DoStep + fmi2GetReal all Real "
           "outputs), median (min) of %zu passes of %zu samples\n",
           passes, samples);
    for (size_t i = 0; i < n; i++) {
        Model *m = &models[i];
        printf("  %-14s %8.1f ns (%.1f)", m->label, median(m->ns, passes), minimum(m->ns, passes));
        if (i) printf("   %.2fx %s", ratio[i], models[0].label);
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
            fprintf(f, ", \"real_inputs\": %zu, \"real_outputs\": %zu, "
                       "\"median_ns_per_sample\": %.2f, \"min_ns_per_sample\": %.2f, "
                       "\"ns_per_sample\": [",
                    m->n_in, m->n_out, median(m->ns, passes), minimum(m->ns, passes));
            for (size_t p = 0; p < passes; p++) fprintf(f, "%s%.2f", p ? ", " : "", m->ns[p]);
            fprintf(f, "]}%s\n", i + 1 < n ? "," : "");
        }
        fprintf(f, "  },\n  \"ratios_over_baseline\": {");
        for (size_t i = 1; i < n; i++) {
            fprintf(f, "%s", i > 1 ? ", " : "");
            json_string(f, models[i].label);
            fprintf(f, ": %.4f", ratio[i]);
        }
        fprintf(f, "}\n}\n");
        fclose(f);
    }
    double checksum = 0;
    for (size_t i = 0; i < n; i++) checksum += models[i].checksum;
    if (!isfinite(checksum)) die("non-finite outputs");
    for (size_t i = 0; i < n; i++) models[i].free_instance(models[i].c);
    return 0;
}
