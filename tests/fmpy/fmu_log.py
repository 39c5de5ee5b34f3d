"""Capturing an FMU's log messages in fmpy (formatted by fmpy's native proxy, which
applies the variadic "%s" arguments the way a C importer would)."""

from fmpy.fmi2 import (fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, calloc, free)
from fmpy.logging import addLoggerProxy
from ctypes import byref


class CapturedLog:
    def __init__(self):
        self.records = []  # (status, category, message)

        def log(_env, _name, status, category, message):
            self.records.append((status, category.decode(), message.decode()))

        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(log)
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        addLoggerProxy(byref(self.callbacks))

    def errors(self):
        return [m for s, _c, m in self.records if s == 3]

    def warnings(self):
        return [m for s, _c, m in self.records if s == 1]

    @property
    def messages(self):
        return [m for _s, _c, m in self.records]
