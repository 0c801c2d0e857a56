"""Run a benchmark and keep its output as a page of the documentation, with when, where and what.

    python benchmarks/record.py bench_sim.py [ARGS ...]

writes ``docs/benchmarks/bench_sim.md``: the date (UTC), the commit (``+`` when the tree has
uncommitted changes), the machine (CPU, cores, memory, OS, Python, numpy and pinocchio), the load
averages before and after, the command, and the benchmark's printed output as it came. The
documentation's Benchmarks page lists every such page, so a re-run replaces the numbers it shows.
"""

from __future__ import annotations

import datetime
import os
import platform
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "benchmarks"


def _git(*args: str) -> str:
    return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()


def _cpu() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _memory_gb() -> str:
    try:
        pages, size = os.sysconf("SC_PHYS_PAGES"), os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return "unknown"
    return f"{pages * size / 1e9:.1f} GB"


def _load() -> str:
    return ", ".join(f"{x:.2f}" for x in os.getloadavg())


def main(argv: list[str]) -> int:
    if not argv or not (ROOT / "benchmarks" / argv[0]).is_file():
        print(__doc__, file=sys.stderr)
        return 2
    script, args = argv[0], argv[1:]
    command = ["python", f"benchmarks/{script}", *args]
    dirty = _git("status", "--porcelain", "--untracked-files=no")
    commit = _git("rev-parse", "--short", "HEAD") + ("+" if dirty else "")
    started = datetime.datetime.now(datetime.UTC)
    load_before = _load()
    result = subprocess.run([sys.executable, *command[1:]], cwd=ROOT, capture_output=True, text=True)
    if result.returncode != 0:
        print(result.stdout + result.stderr, file=sys.stderr)
        return result.returncode
    fence = "`" * 3
    page = f"""# `{script}`

| | |
|---|---|
| date | {started:%Y-%m-%d %H:%M} UTC |
| commit | `{commit}` |
| machine | {_cpu()}, {os.cpu_count()} logical cores, {_memory_gb()}; {platform.system()} {platform.release()} |
| software | Python {platform.python_version()}, numpy {version("numpy")}, pin {version("pin")}, \
viser {version("viser")} |
| load average (1, 5, 15 min) | before {load_before}; after {_load()} |
| command | `{" ".join(command)}` |

{fence}text
{result.stdout.rstrip()}
{fence}
"""
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / f"{Path(script).stem}.md").write_text(page)
    print(f"wrote {(OUT / f'{Path(script).stem}.md').relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
