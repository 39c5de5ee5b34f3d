"""Engine: FMUs' log messages kept in Python: fmpy's FMI 2.0 callbacks with a logger that
collects the messages (formatted by fmpy's native proxy, which applies the variadic "%s"
arguments the way a C importer would), and FMI 3.0's log callback (the message itself, no
format). Used by the masters, the campaigns' runner and the tests."""

from ctypes import byref

from fmpy.fmi2 import (fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, calloc, free)
from fmpy.logging import addLoggerProxy

# fmi2Status, the status a message is logged with.
OK, WARNING, DISCARD, ERROR, FATAL = range(5)


def _text(value):
    return "" if value is None else value.decode(errors="replace")


class FmuLog:
    """Give `callbacks` to FMU2Slave.instantiate, or `fmi3_callback(name)` to
    FMU3Slave.instantiate as its logMessage; `records` then holds every message of status
    `least` or worse, as (instance name, status, category, message)."""

    def __init__(self, least=OK):
        self.records = []
        self.least = least

        def log(_env, name, status, category, message):
            if status >= least:
                self.records.append((_text(name), status, _text(category), _text(message)))

        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(log)
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        addLoggerProxy(byref(self.callbacks))

    def fmi3_callback(self, name):
        """FMI 3.0's log callback for the instance `name` (FMI 3.0 passes no instance name)."""
        def log(_env, status, category, message):
            if status >= self.least:
                self.records.append((name, status, _text(category), _text(message)))
        return log

    def clear(self):
        self.records.clear()

    @property
    def messages(self):
        return [m for _n, _s, _c, m in self.records]

    def errors(self):
        """The messages logged with fmi2Error."""
        return [m for _n, s, _c, m in self.records if s == ERROR]

    def warnings(self):
        """The messages logged with fmi2Warning."""
        return [m for _n, s, _c, m in self.records if s == WARNING]

    def failures(self):
        """"instance: message" of every message logged with fmi2Error or fmi2Fatal."""
        return [f"{n}: {m}" for n, s, _c, m in self.records if s >= ERROR]
