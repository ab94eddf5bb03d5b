"""Numpy's huge-page advice is off in a washbench process (washbench.io.pages), unless the user chose."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from washbench.io.pages import NUMPY_HUGEPAGE_ENV

# numpy's switch returns the value it had: what numpy set at import (or what small_pages set afterwards)
PROBE = (
    "import os\n"
    "{before}\n"
    "import numpy\n"
    "{after}\n"
    "print(numpy._core.multiarray._set_madvise_hugepage(True), os.environ.get('NUMPY_MADVISE_HUGEPAGE'))\n"
)
CALL = "from washbench.io.pages import small_pages; small_pages()"


def python(code: str, env_value: str | None = None) -> str:
    """The output of ``python -c code`` with ``NUMPY_MADVISE_HUGEPAGE`` = ``env_value`` (None: unset)."""
    env = {k: v for k, v in os.environ.items() if k != NUMPY_HUGEPAGE_ENV}
    if env_value is not None:
        env[NUMPY_HUGEPAGE_ENV] = env_value
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True).stdout


def advice(before: str, after: str, env_value: str | None) -> str:
    return python(PROBE.format(before=before, after=after), env_value)


@pytest.mark.skipif(sys.platform != "linux", reason="numpy advises huge pages on Linux only")
def test_numpy_advises_huge_pages_by_default_here() -> None:
    """The premise: without washbench's setting numpy advises them (so the tests below can tell a difference)."""
    assert advice("", "", None).split() == ["True", "None"]


def test_set_before_numpy_is_imported() -> None:
    assert advice(CALL, "", None).split() == ["False", "0"]


def test_set_after_numpy_is_imported() -> None:
    assert advice("", CALL, None).split() == ["False", "0"]


@pytest.mark.skipif(sys.platform != "linux", reason="numpy advises huge pages on Linux only")
def test_the_users_own_choice_stands() -> None:
    assert advice(CALL, "", "1").split() == ["True", "1"]
    assert advice("", CALL, "1").split() == ["True", "1"]


def test_an_empty_setting_is_no_choice() -> None:
    """``NUMPY_MADVISE_HUGEPAGE=`` (empty) would make numpy's own import fail (int('')): taken as unset."""
    assert advice(CALL, "", "").split() == ["False", "0"]


def test_the_command_and_what_it_starts_inherit_it() -> None:
    """``python -m washbench``: the entry point sets it before the command imports numpy (a stand-in command
    here, which reports numpy's switch and what a process it starts sees)."""
    code = (
        "import subprocess, sys, types\n"
        "from washbench.__main__ import entry\n"
        "assert 'numpy' not in sys.modules\n"
        "def main():\n"
        "    import numpy\n"
        "    child = [sys.executable, '-c', 'import os; print(os.environ[\"NUMPY_MADVISE_HUGEPAGE\"])']\n"
        "    seen = subprocess.run(child, capture_output=True, text=True).stdout.strip()\n"
        "    print(numpy._core.multiarray._set_madvise_hugepage(True), seen)\n"
        "    return 0\n"
        "cli = types.ModuleType('washbench.cli')\n"
        "cli.main = main\n"
        "sys.modules['washbench.cli'] = cli\n"
        "sys.exit(entry())\n"
    )
    assert python(code).split() == ["False", "0"]
