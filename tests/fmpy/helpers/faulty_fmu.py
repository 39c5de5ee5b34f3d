"""A foreign FMU that misbehaves on purpose, built from C in the test (gcc): `Faulty`, FMI 2.0
Co-Simulation, one Real input `u` and one Real output `y` (y follows u: y = u at each step's
end), and at `fault_time` its fmi2DoStep does what the Integer parameter `fault` says: 0
nothing, 1 dereferences NULL (SIGSEGV), 2 spins forever. Every other fmi2 function a master
may look up exists and returns fmi2Error where it does nothing."""

import subprocess
import zipfile
from pathlib import Path

GUID = "{5c0e5a77-1c4e-4d0c-9a44-000000000fa1}"
NONE, SEGFAULT, HANG = 0, 1, 2

SOURCE = r"""
#include <stdlib.h>
#include <string.h>
typedef void *C;
typedef unsigned int VR;
typedef struct { double u, y, fault_time; int fault; } M;
#define OK 0
#define ERR 3
#define EXPORT __attribute__((visibility("default")))
EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }
EXPORT int fmi2SetDebugLogging(C c, int on, size_t n, const char *const *cats) { return OK; }
EXPORT C fmi2Instantiate(const char *name, int type, const char *guid, const char *res,
                         const void *callbacks, int visible, int logging) {
    M *m = calloc(1, sizeof(M));
    m->fault_time = 0.0;
    return m;
}
EXPORT void fmi2FreeInstance(C c) { free(c); }
EXPORT int fmi2SetupExperiment(C c, int td, double tol, double start, int sd, double stop) { return OK; }
EXPORT int fmi2EnterInitializationMode(C c) { return OK; }
EXPORT int fmi2ExitInitializationMode(C c) { return OK; }
EXPORT int fmi2Terminate(C c) { return OK; }
EXPORT int fmi2Reset(C c) { M *m = c; memset(m, 0, sizeof(M)); return OK; }
EXPORT int fmi2GetReal(C c, const VR *vr, size_t n, double *v) {
    M *m = c;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) { case 0: v[i] = m->u; break; case 1: v[i] = m->y; break;
                         case 2: v[i] = m->fault_time; break; default: return ERR; }
    }
    return OK;
}
EXPORT int fmi2SetReal(C c, const VR *vr, size_t n, const double *v) {
    M *m = c;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) { case 0: m->u = v[i]; break; case 2: m->fault_time = v[i]; break;
                         default: return ERR; }
    }
    return OK;
}
EXPORT int fmi2GetInteger(C c, const VR *vr, size_t n, int *v) {
    M *m = c;
    for (size_t i = 0; i < n; i++) { if (vr[i] != 3) return ERR; v[i] = m->fault; }
    return OK;
}
EXPORT int fmi2SetInteger(C c, const VR *vr, size_t n, const int *v) {
    M *m = c;
    for (size_t i = 0; i < n; i++) { if (vr[i] != 3) return ERR; m->fault = v[i]; }
    return OK;
}
EXPORT int fmi2GetBoolean(C c, const VR *vr, size_t n, int *v) { return n ? ERR : OK; }
EXPORT int fmi2SetBoolean(C c, const VR *vr, size_t n, const int *v) { return n ? ERR : OK; }
EXPORT int fmi2GetString(C c, const VR *vr, size_t n, const char **v) { return n ? ERR : OK; }
EXPORT int fmi2SetString(C c, const VR *vr, size_t n, const char *const *v) { return n ? ERR : OK; }
EXPORT int fmi2DoStep(C c, double t, double h, int no_prior) {
    M *m = c;
    if (m->fault != 0 && t >= m->fault_time) {
        if (m->fault == 1) { volatile int *nothing = NULL; *nothing = 1; }
        if (m->fault == 2) { volatile int spin = 1; while (spin) {} }
    }
    m->y = m->u;
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

DESCRIPTION = f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Faulty" guid="{GUID}" generationTool="gcc">
  <CoSimulation modelIdentifier="Faulty" canHandleVariableCommunicationStepSize="true"/>
  <ModelVariables>
    <ScalarVariable name="u" valueReference="0" causality="input" variability="continuous"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="y" valueReference="1" causality="output" variability="continuous" initial="exact"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="fault_time" valueReference="2" causality="parameter" variability="fixed"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="fault" valueReference="3" causality="parameter" variability="fixed"><Integer start="0"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="2"/></Outputs><InitialUnknowns><Unknown index="2"/></InitialUnknowns></ModelStructure>
</fmiModelDescription>
"""

# Two Faulty units in a ring: a's y feeds b's u and back (values stay 0; the fault is what
# matters).
LOOP = """<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="1.0" name="faulty">
  <ssd:System name="faulty">
    <ssd:Elements>
      <ssd:Component name="a" source="Faulty.fmu">
        <ssd:Connectors>
          <ssd:Connector name="u" kind="input"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="y" kind="output"><ssc:Real/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
      <ssd:Component name="b" source="Faulty.fmu">
        <ssd:Connectors>
          <ssd:Connector name="u" kind="input"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="y" kind="output"><ssc:Real/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="a" startConnector="y" endElement="b" endConnector="u"/>
      <ssd:Connection startElement="b" startConnector="y" endElement="a" endConnector="u"/>
    </ssd:Connections>
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
