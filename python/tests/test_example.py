"""The documented Python example runs and writes its PNG."""
import os
import subprocess
import sys


def test_density_example(source_dir, tmp_path):
    out = tmp_path / "density.png"
    r = subprocess.run([sys.executable, str(source_dir / "docs" / "python-density.py"),
                        str(source_dir / "scenarios" / "bottleneck.json"), "--seconds", "5",
                        "--out", str(out)], capture_output=True, text=True, env=os.environ)
    assert r.returncode == 0, r.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "persons/m²" in r.stdout
