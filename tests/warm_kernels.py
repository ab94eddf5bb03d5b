"""Fill numba's cache once, before parallel test workers need it (``tests/conftest.py``).

    python tests/warm_kernels.py FOLDER

Installing washbench compiles its kernels into the package (``setup.py`` runs
:mod:`washbench.numerics.precompile`); this script runs the same module, which then loads them (a few seconds). It
compiles them only where the install did not (a build with ``WASHBENCH_NO_PRECOMPILE``, another numba, sources
edited since): then in two lanes side by side (two cores) once, instead of each pytest-xdist worker (and each
``washbench`` process a test starts) compiling the kernels it needs itself, several at the same time (numba has no
lock between processes, so a kernel two processes need at once is compiled twice). That the module covers every
kernel the commands run is tested (``tests/test_precompile.py``).

Then it writes ``FOLDER/done`` with its exit status; the workers wait for that file before their first test.
A failure here fails nothing: the tests that need a kernel compile it themselves and report what is wrong.

First, where Python is told not to write bytecode (``PYTHONDONTWRITEBYTECODE``, set on these machines), it writes
washbench's ``.pyc`` files once (0.2 s): otherwise each of the test run's 300-odd ``washbench`` processes compiles
the modules it imports from source again (about 0.09 s of CPU each for a ``run``).
"""

from __future__ import annotations

import compileall
import importlib.util
import subprocess
import sys
from pathlib import Path


def main(folder: Path) -> int:
    status = None
    try:
        if sys.dont_write_bytecode:  # Python reads .pyc files all the same; compileall writes them regardless
            spec = importlib.util.find_spec("washbench")
            if spec is not None and spec.origin is not None:
                compileall.compile_dir(Path(spec.origin).parent, quiet=2)
        folder.mkdir(parents=True, exist_ok=True)
        status = subprocess.run([sys.executable, "-m", "washbench.numerics.precompile"], stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL).returncode  # fmt: skip
    finally:
        (folder / "done").write_text(f"{status}\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(Path(sys.argv[1])))
