"""A foreign FMU that misbehaves on purpose, built from C in the test (gcc): model identifier
`Faulty`, FMI 2.0 Co-Simulation, a stand-in for the XY plant (model name XYServoPlant, so a
campaign takes it as the plant): velocity commands `u.x`, `u.y` in, positions `pos.x`,
`pos.y` out (ideal axes: pos += u·h), starting at `pos0.*`. At `fault_time` its fmi2DoStep
does what the Integer parameter `fault` says: 0 nothing, 1 dereferences NULL (SIGSEGV), 2
spins forever, 3 prints a line on standard output at every step from then on, 4 returns
fmi2Fatal, 5 spins forever in every third run of its process (runs counted by
fmi2ExitInitializationMode: a tuner's candidates hang now and then). Every other fmi2 function a master may look up exists and returns fmi2Error
where it does nothing."""

import subprocess
import zipfile
from pathlib import Path

GUID = "{5c0e5a77-1c4e-4d0c-9a44-000000000fa1}"
NONE, SEGFAULT, HANG, CHATTY, FATAL, HANG_EVERY_THIRD_RUN = 0, 1, 2, 3, 4, 5

SOURCE = r"""
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
typedef void *C;
typedef unsigned int VR;
/* Reals by value reference: 0 u.x, 1 u.y, 2 pos.x, 3 pos.y, 4 pos0.x, 5 pos0.y, 6 fault_time. */
typedef struct { double r[7]; int fault; } M;
#define OK 0
#define ERR 3
#define EXPORT __attribute__((visibility("default")))
EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }
EXPORT int fmi2SetDebugLogging(C c, int on, size_t n, const char *const *cats) { return OK; }
EXPORT C fmi2Instantiate(const char *name, int type, const char *guid, const char *res,
                         const void *callbacks, int visible, int logging) {
    return calloc(1, sizeof(M));
}
EXPORT void fmi2FreeInstance(C c) { free(c); }
EXPORT int fmi2SetupExperiment(C c, int td, double tol, double start, int sd, double stop) { return OK; }
EXPORT int fmi2EnterInitializationMode(C c) { return OK; }
static int runs = 0;
EXPORT int fmi2ExitInitializationMode(C c) {
    M *m = c;
    runs++;
    m->r[2] = m->r[4];
    m->r[3] = m->r[5];
    return OK;
}
EXPORT int fmi2Terminate(C c) { return OK; }
EXPORT int fmi2Reset(C c) { memset(c, 0, sizeof(M)); return OK; }
EXPORT int fmi2GetReal(C c, const VR *vr, size_t n, double *v) {
    M *m = c;
    for (size_t i = 0; i < n; i++) { if (vr[i] > 6) return ERR; v[i] = m->r[vr[i]]; }
    return OK;
}
EXPORT int fmi2SetReal(C c, const VR *vr, size_t n, const double *v) {
    M *m = c;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] > 6 || vr[i] == 2 || vr[i] == 3) return ERR;
        m->r[vr[i]] = v[i];
    }
    return OK;
}
EXPORT int fmi2GetInteger(C c, const VR *vr, size_t n, int *v) {
    M *m = c;
    for (size_t i = 0; i < n; i++) { if (vr[i] != 7) return ERR; v[i] = m->fault; }
    return OK;
}
EXPORT int fmi2SetInteger(C c, const VR *vr, size_t n, const int *v) {
    M *m = c;
    for (size_t i = 0; i < n; i++) { if (vr[i] != 7) return ERR; m->fault = v[i]; }
    return OK;
}
EXPORT int fmi2GetBoolean(C c, const VR *vr, size_t n, int *v) { return n ? ERR : OK; }
EXPORT int fmi2SetBoolean(C c, const VR *vr, size_t n, const int *v) { return n ? ERR : OK; }
EXPORT int fmi2GetString(C c, const VR *vr, size_t n, const char **v) { return n ? ERR : OK; }
EXPORT int fmi2SetString(C c, const VR *vr, size_t n, const char *const *v) { return n ? ERR : OK; }
EXPORT int fmi2DoStep(C c, double t, double h, int no_prior) {
    M *m = c;
    if (m->fault != 0 && t >= m->r[6]) {
        if (m->fault == 1) { volatile int *nothing = NULL; *nothing = 1; }
        if (m->fault == 2) { volatile int spin = 1; while (spin) {} }
        if (m->fault == 3) { printf("chatty FMU at t = %g\\n", t); }
        if (m->fault == 4) { return 4; }
        if (m->fault == 5 && runs % 3 == 0) { volatile int spin = 1; while (spin) {} }
    }
    m->r[2] += m->r[0] * h;
    m->r[3] += m->r[1] * h;
    return OK;
}
EXPORT int fmi2CancelStep(C c) { return ERR; }
EXPORT int fmi2GetStatus(C c, int kind, int *v) { return ERR; }
EXPORT int fmi2GetRealStatus(C c, int kind, double *v) { return ERR; }
EXPORT int fmi2GetIntegerStatus(C c, int kind, int *v) { return ERR; }
EXPORT int fmi2GetBooleanStatus(C c, int kind, int *v) { return ERR; }
EXPORT int fmi2GetStringStatus(C c, int kind, const char **v) { return ERR; }
EXPORT int fmi2GetFMUstate(C c, void **s) { return ERR; }
EXPORT int fmi2SetFMUstate(C c, void *s) { return ERR; }
EXPORT int fmi2FreeFMUstate(C c, void **s) { return ERR; }
EXPORT int fmi2SerializedFMUstateSize(C c, void *s, size_t *n) { return ERR; }
EXPORT int fmi2SerializeFMUstate(C c, void *s, char *b, size_t n) { return ERR; }
EXPORT int fmi2DeSerializeFMUstate(C c, const char *b, size_t n, void **s) { return ERR; }
EXPORT int fmi2GetDirectionalDerivative(C c, const VR *a, size_t na, const VR *b, size_t nb,
                                        const double *dv, double *df) { return ERR; }
EXPORT int fmi2SetRealInputDerivatives(C c, const VR *vr, size_t n, const int *o, const double *v) { return ERR; }
EXPORT int fmi2GetRealOutputDerivatives(C c, const VR *vr, size_t n, const int *o, double *v) { return ERR; }
"""

def _real(name, vr, causality, unit="mm"):
    variability = "fixed" if causality == "parameter" else "continuous"
    initial = ' initial="exact"' if causality == "output" else ""
    start = ' start="0"'
    return (f'<ScalarVariable name="{name}" valueReference="{vr}" causality="{causality}" '
            f'variability="{variability}"{initial}><Real unit="{unit}"{start}/></ScalarVariable>')


DESCRIPTION = f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="XYServoPlant" guid="{GUID}" generationTool="gcc"
    description="A misbehaving stand-in for the XY plant (tests/fmpy/helpers/faulty_fmu.py)">
  <CoSimulation modelIdentifier="Faulty" canHandleVariableCommunicationStepSize="true"/>
  <UnitDefinitions><Unit name="mm"/><Unit name="mm/s"/><Unit name="s"/></UnitDefinitions>
  <ModelVariables>
    {_real("u.x", 0, "input", "mm/s")}
    {_real("u.y", 1, "input", "mm/s")}
    {_real("pos.x", 2, "output")}
    {_real("pos.y", 3, "output")}
    {_real("pos0.x", 4, "parameter")}
    {_real("pos0.y", 5, "parameter")}
    {_real("fault_time", 6, "parameter", "s")}
    <ScalarVariable name="fault" valueReference="7" causality="parameter" variability="fixed"><Integer start="0"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="3"/><Unknown index="4"/></Outputs>
    <InitialUnknowns><Unknown index="3"/><Unknown index="4"/></InitialUnknowns></ModelStructure>
</fmiModelDescription>
"""

# Two Faulty units side by side, unconnected (a position onto a velocity command is a
# unit mismatch the master refuses).
LOOP = """<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="1.0" name="faulty">
  <ssd:System name="faulty">
    <ssd:Elements>
      <ssd:Component name="a" source="Faulty.fmu">
        <ssd:Connectors>
          <ssd:Connector name="u.x" kind="input"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="pos.x" kind="output"><ssc:Real/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
      <ssd:Component name="b" source="Faulty.fmu">
        <ssd:Connectors>
          <ssd:Connector name="u.x" kind="input"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="pos.x" kind="output"><ssc:Real/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
  </ssd:System>
</ssd:SystemStructureDescription>
"""


def build(folder):
    """Writes Faulty.fmu and faulty.ssd (the ring) into `folder`; returns the .ssd's path."""
    folder = Path(folder)
    source, library = folder / "faulty.c", folder / "Faulty.so"
    source.write_text(SOURCE)
    subprocess.run(["cc", "-O1", "-shared", "-fPIC", "-fvisibility=hidden", "-o", str(library),
                    str(source)], check=True)
    with zipfile.ZipFile(folder / "Faulty.fmu", "w") as z:
        z.writestr("modelDescription.xml", DESCRIPTION)
        z.write(library, "binaries/linux64/Faulty.so")
    (folder / "faulty.ssd").write_text(LOOP)
    return folder / "faulty.ssd"
