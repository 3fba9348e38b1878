# docs/api/python.md is what docs/api/generate_python.py writes from the package's docstrings.
import subprocess
import sys

from conftest import ROOT


def test_python_api_reference_is_current():
    r = subprocess.run([sys.executable, str(ROOT / "docs" / "api" / "generate_python.py"), str(ROOT), "--check"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
