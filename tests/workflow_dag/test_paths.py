"""The path provider: one pattern per folder, concrete paths from the same call, runs apart."""

from amontons.workflow.paths import SOLVE, RunPaths, figure_files, flat_files


def test_a_path_without_wildcard_values_is_the_rules_pattern():
    paths = RunPaths("small")
    assert paths.scene(SOLVE) == "results/small/{material}/{sphere}/scenes/{scene}/solve.json"
    assert paths.scene(SOLVE, "PS", "PS-1", "elastic") == (
        "results/small/PS/PS-1/scenes/elastic/solve.json"
    )
    assert paths.measured() == "results/small/{material}/{sphere}/measure"
    assert paths.scan_value("x.json", "PS", "s", "k", "5") == (
        "results/small/PS/s/scans/k/values/5/x.json"
    )
    assert paths.scan_values("PS", "s", "k") == "results/small/PS/s/scans/k/values"


def test_two_runs_share_no_folder():
    small, full = RunPaths("small"), RunPaths("full")
    folders = ("results", "logs", "synthetic", "study_results", "accuracy", "accuracy_logs")
    for name in folders:
        assert getattr(small, name) != getattr(full, name)
        assert "small" in getattr(small, name)
    assert small.synthetic_sphere("PS") == "resources/synthetic/small/PS"


def test_a_figure_is_its_png_pdf_and_csv():
    assert figure_files("f", "B8") == ["f/B8.png", "f/B8.pdf", "f/B8.csv"]


def test_flat_files_lists_a_nested_layout_in_order():
    assert flat_files({"a": "1", "b": ["2", {"c": "3"}]}) == ["1", "2", "3"]
