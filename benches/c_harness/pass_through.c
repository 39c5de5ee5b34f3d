/* PassThroughC: a bare FMI 2.0 Co-Simulation model in C, the floor of benches/c_harness.
 *
 * Four Real inputs in1..in4 (value references 0..3) are copied on fmi2DoStep to four Real
 * outputs out1..out4 (4..7); benches/c_harness/PassThroughC.xml is its model description.
 * No handle registry, no state machine table, no logging: the fmi2Component is the
 * address of the instance, checked against NULL only, and every call does what an
 * importer cannot do without (argument checks, the mode, the copy). This is what a
 * framework-free C model costs through the same dlopen'ed calls, so the harness's
 * plant / bare ratio is the price of everything contour-fmu does around a model (its
 * registry included, which the Rust bench's PassThrough model sits behind too).
 *
 * It exports only the functions the harness calls; built by benches/c_harness/run.sh
 * (gcc -O2 -shared) into <target>/c_harness/PassThroughC.so.
 */

#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#define GUID "{b4c8e2a0-5d1f-4c3b-9a6e-7f0d2c1b3a45}"
#define N_IN 4
#define N_OUT 4

enum mode { INSTANTIATED, INITIALIZATION, STEPPING, TERMINATED };

typedef struct {
    fmi2CallbackFunctions functions;
    enum mode mode;
    fmi2Real time;
    fmi2Real in[N_IN];
    fmi2Real out[N_OUT];
} Instance;

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn) {
    (void)instanceName, (void)fmuResourceLocation, (void)visible, (void)loggingOn;
    if (!functions || fmuType != fmi2CoSimulation || !fmuGUID || strcmp(fmuGUID, GUID) != 0)
        return NULL;
    Instance *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->functions = *functions;
    c->mode = INSTANTIATED;
    return c;
}

void fmi2FreeInstance(fmi2Component c) { free(c); }

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined,
                               fmi2Real tolerance, fmi2Real startTime,
                               fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    (void)toleranceDefined, (void)tolerance, (void)stopTimeDefined, (void)stopTime;
    Instance *m = c;
    if (!m || m->mode != INSTANTIATED) return fmi2Error;
    m->time = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    Instance *m = c;
    if (!m || m->mode != INSTANTIATED) return fmi2Error;
    m->mode = INITIALIZATION;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Instance *m = c;
    if (!m || m->mode != INITIALIZATION) return fmi2Error;
    m->mode = STEPPING;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c) {
    Instance *m = c;
    if (!m || m->mode != STEPPING) return fmi2Error;
    m->mode = TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[]) {
    Instance *m = c;
    if (!m || m->mode == TERMINATED || (nvr && (!vr || !value))) return fmi2Error;
    for (size_t i = 0; i < nvr; i++)
        if (vr[i] >= N_IN) return fmi2Error;
    for (size_t i = 0; i < nvr; i++) m->in[vr[i]] = value[i];
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[]) {
    Instance *m = c;
    if (!m || m->mode == INSTANTIATED || (nvr && (!vr || !value))) return fmi2Error;
    for (size_t i = 0; i < nvr; i++)
        if (vr[i] >= N_IN + N_OUT) return fmi2Error;
    for (size_t i = 0; i < nvr; i++)
        value[i] = vr[i] < N_IN ? m->in[vr[i]] : m->out[vr[i] - N_IN];
    return fmi2OK;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    (void)noSetFMUStatePriorToCurrentPoint;
    Instance *m = c;
    if (!m || m->mode != STEPPING || !(communicationStepSize > 0)) return fmi2Error;
    memcpy(m->out, m->in, sizeof m->out);
    m->time = currentCommunicationPoint + communicationStepSize;
    return fmi2OK;
}
