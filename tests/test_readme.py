"""The README's two commands and CI stay in step."""
from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def readme_commands() -> list[str]:
    text = (ROOT / "README.md").read_text()
    block = text.split("```bash", 1)[1].split("```", 1)[0]
    return [line.strip() for line in block.strip().splitlines()]


def test_readme_opens_with_two_commands_install_and_test():
    first, second = readme_commands()[:2]
    assert first.startswith("pip install") and second.startswith("pip install")
    assert "pytest" in second


def test_ci_runs_the_readme_test_command_verbatim():
    ci = (ROOT / ".ci" / "run").read_text().splitlines()
    assert readme_commands()[1] in [line.strip() for line in ci]


def test_readme_benchmark_tables_are_the_benchmarks_output():
    """Every results file a benchmark wrote is in the README, verbatim, between its
    markers (``python -m tests.benchmarks.tables`` copies them), and nothing else is."""
    from tests.benchmarks import tables
    written = tables.tables()
    assert written, "no benchmark results committed"
    in_readme = tables.readme_tables((ROOT / "README.md").read_text())
    assert sorted(in_readme) == sorted(written)
    stale = [name for name in written if in_readme[name] != written[name]]
    assert not stale, f"README tables differ from tests/benchmarks/results/: {stale}; run " \
                      "python -m tests.benchmarks.tables"


def test_the_table_splicer_replaces_only_marked_tables():
    from tests.benchmarks import tables
    text = "a\n<!-- table:x -->\nold\n<!-- /table:x -->\nb <!-- table:y -->\n"
    assert tables.splice(text, {"x": "new\n"}) == \
        "a\n<!-- table:x -->\nnew\n<!-- /table:x -->\nb <!-- table:y -->\n"
    assert tables.readme_tables(text) == {"x": "old\n"}


def test_readme_names_every_debian_package_ci_installs():
    """A fresh machine set up from the README has what CI installs (the fonts too)."""
    import re
    ci = (ROOT / ".ci" / "run").read_text()
    packages = re.search(r"for pkg in ([^;]+);", ci).group(1).split()
    readme = " ".join((ROOT / "README.md").read_text().split())
    line = re.search(r"`apt-get install ([^`]+)`", readme).group(1).split()
    assert sorted(packages) == sorted(line), (packages, line)
