"""``python -m validation theta-table``: the docs' table of theta against error and cost."""
import pytest

from validation import theta_table


@pytest.fixture(scope="module")
def table():
    return theta_table.measure(3000, thetas=(0.3, 0.7))


def test_rows_for_each_walk_and_theta_with_falling_errors(table):
    rows = table["rows"]
    assert [(r["walk"], r["theta"]) for r in rows] == [("tree", 0.3), ("tree", 0.7),
                                                     ("fmm", 0.3), ("fmm", 0.7)]
    for low, high in ((rows[0], rows[1]), (rows[2], rows[3])):
        assert low["gravity"]["median"] < high["gravity"]["median"]
        for order in (2, 1, 0):
            assert low["plasma"][order]["median"] < high["plasma"][order]["median"]
    for r in rows:
        # the quadrupole beats the dipole, which beats the monopole, on the plasma
        medians = [r["plasma"][order]["median"] for order in (2, 1, 0)]
        assert medians == sorted(medians)
        assert 0.0 < r["gravity"]["median"] < 0.05 and r["gravity_s"] > 0 and r["plasma_s"] > 0


def test_markdown_has_a_line_per_row(table):
    lines = theta_table.markdown(table)
    assert lines[0] == theta_table.HEADER
    assert len(lines) == 2 + len(table["rows"])
    assert all(line.count("|") == lines[0].count("|") for line in lines)


def test_bad_n_is_refused(capsys):
    with pytest.raises(SystemExit):
        theta_table.main(["--n", "1"])
    assert "--n must be at least 2, got 1" in capsys.readouterr().err
