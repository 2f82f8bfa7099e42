"""The machine a bench run measured: processor, cores, threads and versions."""
import os
import platform

import numpy as np


def machine():
    import numba

    cpu = platform.processor() or ""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    info = {"cpu": cpu, "cores": os.cpu_count(), "numba_threads": numba.get_num_threads(),
            "python": platform.python_version(), "numpy": np.__version__,
            "numba": numba.__version__, "platform": platform.platform()}
    try:
        import llvmlite.binding as llvm

        info["llvm_cpu"] = llvm.get_host_cpu_name()
    except Exception:  # informational only
        pass
    try:
        import rebound

        info["rebound"] = rebound.__version__
    except ImportError:
        pass
    return info
