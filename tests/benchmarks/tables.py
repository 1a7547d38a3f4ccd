"""Benchmark tables: written by the benchmark scripts, copied into the README by one command.

A benchmark script ends with :func:`write` (a Markdown table, with the date, the
machine and its load, into ``tests/benchmarks/results/NAME.md``). Then

    python -m tests.benchmarks.tables

copies every results file into README.md between its markers
``<!-- table:NAME -->`` and ``<!-- /table:NAME -->``. ``tests/test_readme.py``
checks that the README holds exactly what the committed results files say, so
no figure in those tables is typed by hand or goes stale unnoticed.
"""
from __future__ import annotations

import datetime
import os
import platform
import re
from pathlib import Path
from typing import Sequence

ROOT = Path(__file__).resolve().parents[2]
RESULTS = Path(__file__).resolve().parent / "results"
README = ROOT / "README.md"
_MARKED = re.compile(r"(<!-- table:(?P<name>[\w-]+) -->\n)(?P<body>.*?)(<!-- /table:(?P=name) -->)",
                     re.S)


def machine() -> str:
    """The processor and the cores this process may use."""
    model = platform.processor() or "unknown processor"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return f"{model}, {cores} cores"


def markdown(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A Markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def write(name: str, header: Sequence[str], rows: Sequence[Sequence[str]], command: str,
          load_before: str) -> Path:
    """Write results file ``NAME.md``: the table, then how and where it was measured."""
    RESULTS.mkdir(exist_ok=True)
    today = datetime.date.today().isoformat()
    load_after = load_average()
    text = (markdown(header, rows) + f"\n`{command}`, {today}, on {machine()}; load average "
            f"{load_before} before, {load_after} after.\n")
    path = RESULTS / f"{name}.md"
    path.write_text(text)
    print(f"wrote {path.relative_to(ROOT)}; copy it into the README with "
          f"`python -m tests.benchmarks.tables`")
    return path


def load_average() -> str:
    """The 1, 5 and 15 minute load averages, as the results files print them."""
    return "/".join(f"{v:.2f}" for v in os.getloadavg())


def peak_bytes() -> int:
    """This process's peak resident memory (``ru_maxrss``, KiB on Linux), in bytes."""
    import resource
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def answer_child(case, child) -> bool:
    """In a ``--child NAME RES METHOD`` process: run ``child(name, int(res), method)``,
    print its JSON for :func:`run_child`, and say so (the script then returns)."""
    if not case:
        return False
    import json
    name, res, method = case
    print(json.dumps(child(name, int(res), method)))
    return True


def run_child(script: str, *args: str) -> dict:
    """Run ``python script --child ARGS`` (a benchmark case in a fresh process, so its
    peak memory is its own): the JSON of its last line, or ``{"error_text": ...}``."""
    import json
    import subprocess
    import sys
    done = subprocess.run([sys.executable, script, "--child", *args], capture_output=True,
                          text=True)
    if done.returncode != 0:
        tail = (done.stderr.strip().splitlines() or ["?"])[-1]
        return {"error_text": tail[:160]}
    return json.loads(done.stdout.strip().splitlines()[-1])


def tables() -> dict[str, str]:
    """The committed results files, by name."""
    return {p.stem: p.read_text() for p in sorted(RESULTS.glob("*.md"))}


def readme_tables(text: str) -> dict[str, str]:
    """The README's marked tables, by name."""
    return {m["name"]: m["body"] for m in _MARKED.finditer(text)}


def splice(text: str, found: dict[str, str]) -> str:
    """``text`` with every marked table replaced by its results file."""
    def replace(m: re.Match) -> str:
        body = found.get(m["name"], m["body"])
        return m.group(1) + body + m.group(4)
    return _MARKED.sub(replace, text)


def main() -> None:
    text = README.read_text()
    new = splice(text, tables())
    missing = sorted(set(tables()) - set(readme_tables(text)))
    README.write_text(new)
    print(f"README: {len(readme_tables(new))} tables"
          + (f"; no markers yet for {', '.join(missing)}" if missing else ""))


if __name__ == "__main__":
    main()
