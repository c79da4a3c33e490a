"""What the README promises, run as a user would copy it."""

import re
import subprocess
import sys

from conftest import ROOT


def python_blocks() -> list[str]:
    """The README's ```python blocks."""
    return re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S)


def test_the_readme_example_runs_and_prints_what_it_says(tmp_path):
    # every block runs as it stands; a "# prints X" line is what the next print shows
    blocks = python_blocks()
    assert blocks
    for code in blocks:
        proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                              text=True, timeout=300)
        assert proc.returncode == 0, proc.stderr
        said = re.search(r"# prints (.*?):", code)
        if said:
            assert proc.stdout.split() == said.group(1).split(), proc.stdout
