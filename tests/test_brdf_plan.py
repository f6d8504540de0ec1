"""brdf.plan: a fabric's compiled form, the only thing the kernel's readers read."""

import ast
import pathlib

import numpy as np
import pytest

import brdf
from brdf.plan import FabricPlan

ROOT = pathlib.Path(__file__).resolve().parents[1]


def test_plan_is_frozen_and_its_arrays_read_only():
    plan = brdf.fabric("silk_shot").plan
    with pytest.raises(AttributeError):
        plan.options = None
    with pytest.raises(AttributeError):
        plan.threads[0].eta = 2.0
    with pytest.raises(ValueError, match="read-only"):
        plan.threads[0].weight[0] = 1.0


def test_thread_constants_from_the_threads():
    fab = brdf.fabric("silk_crepe_de_chine", tangent_samples=7)
    for t, c in zip(fab.threads, fab.plan.threads):
        alpha, weight = t.curve.samples(7)
        np.testing.assert_array_equal(c.ca, np.cos(np.radians(alpha)))
        np.testing.assert_array_equal(c.weight, weight)
        assert (c.gamma_s, c.gamma_v) == (np.radians(t.gamma_s), np.radians(t.gamma_v))
        assert (c.eta, c.kd, c.area, c.albedo) == (t.eta, t.kd, t.area, t.albedo)
    assert fab.plan.samples == max(c.ca.size for c in fab.plan.threads)


def test_plan_eval_is_fabric_eval_and_prepared_reads_the_plan():
    fab = brdf.fabric("polyester_satin_charmeuse", gap="outgoing")
    rng = np.random.default_rng(2)
    wi = brdf.directions.from_angles(rng.uniform(0, 1.5, 40), rng.uniform(-3, 3, 40))
    wo = brdf.directions.from_angles(rng.uniform(0, 1.5, 40), rng.uniform(-3, 3, 40))
    np.testing.assert_array_equal(fab.plan.eval(wi, wo), fab.eval(wi, wo))
    np.testing.assert_array_equal(fab.plan.eval(wi, wo, split=True), fab.eval_threads(wi, wo))
    prep = brdf.Prepared(fab.plan, wi, wo)
    np.testing.assert_allclose(prep.eval(), fab.eval(wi, wo), rtol=1e-13, atol=0)
    assert brdf.Prepared(fab, wi, wo).plan is fab.plan
    with pytest.raises(ValueError, match="fabric must be a brdf.Fabric or a brdf.FabricPlan"):
        brdf.Prepared(fab.threads, wi, wo)
    with pytest.raises(ValueError, match="fabric must be a brdf.Fabric or a brdf.FabricPlan"):
        brdf.sampling.pdf(object(), wo, wi)
    assert brdf.plan.plan_of(fab) is fab.plan and isinstance(fab.plan, FabricPlan)


def _sources():
    for pkg in ("brdf", "gonio", "analysis", "reports", "bench"):
        yield from (ROOT / pkg).rglob("*.py")


def test_no_module_outside_fabric_reads_fabric_private_state():
    private = {"_threads", "_options", "_plan", "_const", "_frames", "_geometry", "_q"}
    found = []
    for path in _sources():
        if path == ROOT / "brdf" / "fabric.py":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (isinstance(node, ast.Attribute) and node.attr in private
                    and not (isinstance(node.value, ast.Name) and node.value.id == "self")):
                found.append(f"{path.relative_to(ROOT)}:{node.lineno} .{node.attr}")
    assert found == []


def test_prepared_and_plan_do_not_import_fabric():
    for name in ("prepared", "plan", "sampling"):
        tree = ast.parse((ROOT / "brdf" / f"{name}.py").read_text(encoding="utf-8"))
        mods = {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
        mods |= {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
        assert "brdf.fabric" not in mods and "brdf.presets" not in mods, name
