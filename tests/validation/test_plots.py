"""The report's plots: every line drawn distinctly, work-precision lines in order of cost."""
import matplotlib.colors as mcolors

from validation import plots


def _captured(monkeypatch):
    figures = []
    monkeypatch.setattr(plots, "_save", lambda fig, path: figures.append(fig))
    return figures


def _look(line):
    return (mcolors.to_hex(line.get_color()), line.get_linestyle())


def test_every_method_in_the_style_table_is_drawn_its_own_way():
    looks = [(mcolors.to_hex(c), ls) for c, ls, _ in plots.STYLE.values()]
    assert len(set(looks)) == len(looks)


def test_a_method_at_two_settings_and_unknown_methods_get_distinct_lines():
    keys = [("engine:euler", "500 steps"), ("engine:euler", "1e5 steps"),
            ("engine:leapfrog", "500 steps"), ("x:new", ""), ("y:new", ""), ("x:new", "other")]
    styles = plots.line_styles(keys)
    looks = [styles[k][:2] for k in keys]
    assert len(set(looks)) == len(keys)
    assert styles[keys[0]][0] == styles[keys[1]][0]  # one method keeps its colour
    assert styles[keys[3]][0] == styles[keys[5]][0] != styles[keys[4]][0]


def test_the_energy_drift_plot_draws_each_run_distinctly(monkeypatch):
    figures = _captured(monkeypatch)
    runs = [{"method": m, "setting": s, "t": [1.0, 2.0, 4.0], "err": [1e-9, 2e-9, 4e-9],
             "growth_exponent": 1.0}
            for m, s in (("engine:euler", "500 steps/orbit"), ("engine:euler", "1e5 steps/orbit"),
                         ("engine:leapfrog", "500 steps/orbit"), ("rebound:whfast", "500"))]
    section = {"kepler": {"title": "Kepler", "time_unit": 1.0, "time_unit_name": "P",
                          "runs": runs}}
    plots.energy_drift(section, "unused.png")
    lines = figures[0].axes[0].get_lines()
    assert len(lines) == 4
    assert len({_look(line) for line in lines}) == 4


def test_work_precision_lines_follow_the_cost(monkeypatch):
    runs = [{"method": "rebound:saba", "evaluations": e, "time_s": e * 1e-6, "error": err}
            for e, err in ((3000, 1e-9), (800, 1e-6), (16000, 1e-12), (1700, 1e-7))]
    runs += [{"method": "rebound:saba", "evaluations": 50, "time_s": 1e-5, "error": None},
             {"method": "rebound:saba", "evaluations": 60, "time_s": 1e-5, "error": 1e3},
             {"method": "engine:saba", "evaluations": 900, "time_s": 1e-3, "error": 1e-8}]
    lines = plots.work_precision_lines({"runs": runs})
    assert [r["evaluations"] for r in lines["rebound:saba"]] == [800, 1700, 3000, 16000]
    assert [r["evaluations"] for r in lines["engine:saba"]] == [900]

    figures = _captured(monkeypatch)
    plots.work_precision({"runs": runs, "metric": "position", "length_name": "a",
                          "title": "Kepler", "reference": {"floor": 0.0}}, "unused.png")
    for ax in figures[0].axes[:2]:
        saba = next(line for line in ax.get_lines() if line.get_label() == "REBOUND saba")
        assert list(saba.get_xdata()) == [1e-6, 1e-7, 1e-9, 1e-12]
        assert len({_look(line) for line in ax.get_lines()}) == len(ax.get_lines())
