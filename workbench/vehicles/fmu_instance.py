"""One running instance of a checked plant FMU (`fmu_description.FmuInterface`), FMI 2.0 or 3.0 co-simulation,
through FMPy: extracted once into a private temporary folder, (re)started with start values, its real inputs set,
stepped, its real outputs read.

A `doStep` that fails (an error or fatal status, or FMI 3.0's terminateSimulation or early return) raises
PlantStepError with the time, the status and the FMU's last log messages; the simulator ends the run with status
`plant_failed` on it, and every other caller sees a WorkbenchInputError (the CLIs print it as one line). The FMU's
log messages are kept (the last MAX_LOG_MESSAGES), never printed.
"""

from __future__ import annotations

import shutil
import tempfile
import weakref
from collections import deque
from ctypes import byref
from typing import Any

from workbench.base.errors import WorkbenchInputError
from workbench.vehicles.base import PlantStepError
from workbench.vehicles.fmu_description import FmuInterface

#: How many of the FMU's latest log messages are kept for an error message.
MAX_LOG_MESSAGES = 5
_STATUS_NAMES = ("ok", "warning", "discard", "error", "fatal", "pending")


class FmuInstance:
    """A started plant FMU (module docstring). `start` (re)initialises it; `set_inputs`, `step` and `outputs`
    run it; `set_parameter` changes a tunable parameter between steps."""

    def __init__(self, interface: FmuInterface) -> None:
        import fmpy

        self.interface = interface
        self.log: deque[str] = deque(maxlen=MAX_LOG_MESSAGES)
        self._folder = tempfile.mkdtemp(prefix="workbench-fmu-")
        self._fmu: Any = None
        self._instantiated = False
        self.time_s = 0.0
        try:
            fmpy.extract(str(interface.path), self._folder)
        except Exception as exc:  # a damaged archive: whatever the zip reader raises
            shutil.rmtree(self._folder, ignore_errors=True)
            raise WorkbenchInputError(f"plant FMU {str(interface.path)!r}: cannot be extracted ({exc})") from None
        self._finalizer = weakref.finalize(self, _release, self._folder, [None])

    def _load(self) -> None:
        """Load the binary and instantiate (once; a later `start` resets instead)."""
        from fmpy.fmi2 import FMU2Slave
        from fmpy.fmi3 import FMU3Slave

        i = self.interface
        cls = FMU2Slave if i.fmi_major == 2 else FMU3Slave
        fmu = cls(guid=i.guid, unzipDirectory=self._folder, modelIdentifier=i.model_identifier, instanceName="plant")
        if i.fmi_major == 2:
            self._callbacks = _fmi2_callbacks(self.log)
            fmu.instantiate(callbacks=self._callbacks, loggingOn=True)
            self._get, self._set = fmu.getReal, fmu.setReal
        else:
            fmu.instantiate(loggingOn=True, logMessage=_fmi3_logger(self.log))
            self._get, self._set = fmu.getFloat64, fmu.setFloat64
        self._fmu = fmu
        self._finalizer.detach()
        self._finalizer = weakref.finalize(self, _release, self._folder, [fmu])

    def start(self, start_values: dict[int, float]) -> None:
        """Initialise at time 0 with these parameter values (value reference -> value), ready to step."""
        try:
            if self._fmu is None:
                self._load()
            else:
                self._fmu.reset()
            fmu = self._fmu
            if self.interface.fmi_major == 2:
                fmu.setupExperiment(startTime=0.0)
                fmu.enterInitializationMode()
            else:
                fmu.enterInitializationMode(startTime=0.0)
            if start_values:
                self._set(list(start_values), list(start_values.values()))
            fmu.exitInitializationMode()
        except WorkbenchInputError:
            raise
        except Exception as exc:  # FMPy's FMICallException, or an instantiation that failed
            raise WorkbenchInputError(
                f"plant FMU {str(self.interface.path)!r}: initialisation failed ({exc}){self._log_text()}"
            ) from None
        self.time_s = 0.0

    def set_inputs(self, refs: list[int], values: list[float]) -> None:
        """Set real inputs (value references, values)."""
        self._set(refs, values)

    def set_parameter(self, ref: int, value: float) -> None:
        """Set a tunable real parameter between steps."""
        self._set([ref], [value])

    def outputs(self, refs: list[int]) -> list[float]:
        """The real variables with these value references, as the FMU has them now."""
        return self._get(refs)

    def step(self, step_s: float) -> None:
        """One doStep of `step_s` from the current time; PlantStepError when it fails (module docstring)."""
        from fmpy.fmi1 import FMICallException

        try:
            result = self._fmu.doStep(self.time_s, step_s)
        except FMICallException as exc:
            raise PlantStepError(self._failure(str(exc))) from None
        if self.interface.fmi_major == 3 and (result[1] or result[2]):
            what = "asked to terminate the simulation" if result[1] else f"returned early at t = {result[3]:.4f} s"
            raise PlantStepError(self._failure(f"fmi3DoStep {what}"))
        self.time_s += step_s

    def _failure(self, what: str) -> str:
        return f"the plant FMU failed its step at t = {self.time_s:.3f} s: {what}{self._log_text()}"

    def _log_text(self) -> str:
        return f"; the FMU's log: {' | '.join(self.log)}" if self.log else ""

    def close(self) -> None:
        """Free the instance and delete the extracted files (also done when the instance is collected)."""
        self._finalizer()


def _release(folder: str, holder: list[Any]) -> None:
    """Free an FMU instance (if one was made) and delete its extracted folder; errors of a dying FMU are ignored."""
    fmu = holder[0]
    if fmu is not None:
        try:
            fmu.terminate()
        except Exception:  # a failed FMU may refuse to terminate: it is freed all the same
            pass
        try:
            fmu.freeInstance()
        except Exception:  # nothing more can be done for it
            pass
    shutil.rmtree(folder, ignore_errors=True)


def _fmi2_callbacks(log: deque[str]) -> Any:
    """FMI 2.0 callbacks whose logger keeps the messages in `log` (FMPy's proxy formats the variadic message)."""
    from fmpy import calloc, free
    from fmpy.fmi2 import (
        fmi2CallbackAllocateMemoryTYPE,
        fmi2CallbackFreeMemoryTYPE,
        fmi2CallbackFunctions,
        fmi2CallbackLoggerTYPE,
    )
    from fmpy.logging import addLoggerProxy

    def logger(component: Any, instance: bytes, status: int, category: bytes, message: bytes) -> None:
        log.append(f"[{_status_name(status)}] {message.decode('utf-8', 'replace')}")

    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(logger)
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    addLoggerProxy(byref(callbacks))
    return callbacks


def _fmi3_logger(log: deque[str]) -> Any:
    """An FMI 3.0 log-message callback keeping the messages in `log`."""

    def logger(environment: Any, status: int, category: bytes, message: bytes) -> None:
        log.append(f"[{_status_name(status)}] {message.decode('utf-8', 'replace')}")

    return logger


def _status_name(status: int) -> str:
    return _STATUS_NAMES[status] if 0 <= status < len(_STATUS_NAMES) else str(status)
