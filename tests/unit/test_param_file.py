"""Parameter files as typed tables: a misspelt key anywhere is refused with its table and the nearest known
key, a wrong shape or type with the element at fault; ``extends`` merges tables key by key and refuses a
chain; ``[app]`` gives the app's defaults (generic ones without it) and names presets and lessons that exist."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from rns_viz.defaults import FALLBACK_GAINS, MANUAL_EXAGGERATION, defaults_for
from rns_viz.live.teaching.lessons import lessons_for
from rns_viz.model import FsmsModel
from rns_viz.param_file import AppTable, SceneTable
from rns_viz.params import ASSETS_DIR, MODEL_NAMES, ModelFileError, _bundled, load_spec, param_file_for
from rns_viz.scenarios import presets_for
from rns_viz.viz.scene.style import style_for


def copy_of(folder: Path, bundled: str, name: str = "mine", edit: tuple[str, str] | None = None) -> Path:
    """A bundled model's parameter file as ``NAME.toml`` in ``folder`` (its URDF beside it), edited once."""
    text = (ASSETS_DIR / f"{bundled}.toml").read_text()
    (folder / f"{bundled}.urdf").write_bytes((ASSETS_DIR / f"{bundled}.urdf").read_bytes())
    if edit is not None:
        assert edit[0] in text, edit[0]
        text = text.replace(edit[0], edit[1], 1)
    path = folder / f"{name}.toml"
    path.write_text(text)
    return path


def refusal(path: Path) -> str:
    with pytest.raises(ModelFileError) as caught:
        load_spec(path)
    message = str(caught.value)
    assert message.startswith(f"{path}"), message  # the file first
    return message.removeprefix(f"{path}: ")


@pytest.mark.parametrize(
    ("bundled", "edit", "expected"),
    [
        ("trep", ("damping = [[0.0]]", "dampng = [[0.0]]"), "[base] dampng: unknown key (did you mean damping?)"),
        ("trep", ('ee_frame = "ee"', 'ee_fram = "ee"'), "[model] ee_fram: unknown key (did you mean ee_frame?)"),
        ("trep", ("joint_damping = [", "joint_dampings = ["), "[arm] joint_dampings: unknown key (did you mean"),
        (
            "trep2",
            ("compensating = [", "compensatng = ["),
            "[arms] compensatng: unknown key (did you mean compensating?)",
        ),
        ("trep", ("kick_peak_N = 0.8", "kick_peak = 0.8"), "[app] kick_peak: unknown key (did you mean kick_peak_N?)"),
        (
            "trep",
            ("[app.gains.torque]", "[app.gains.torqe]"),
            "[app.gains.torqe]: unknown table (did you mean torque?)",
        ),
        ("trep", ("g_b_per_s = 24.0", "g_b = 24.0"), "[app.gains.velocity] g_b: unknown key (did you mean g_b_per_s?)"),
        (
            "trep",
            ("grid_cell_m = 0.05", "grid_cel_m = 0.05"),
            "[app.scene] grid_cel_m: unknown key (did you mean grid_cell_m?)",
        ),
        (
            "boom7",
            ('kind = "boom", radius_m', 'kind = "boom", radus_m'),
            "[app.scene.base] radus_m: unknown key (did you mean radius_m?)",
        ),
        ("trep", ("[arm]", "[armm]"), "[armm]: unknown table (did you mean arm?)"),
        (
            "trep",
            ('law = "velocity"', 'law = "velocty"'),
            "[app] law: 'velocty' is not allowed (did you mean velocity?)",
        ),
        (
            "trep",
            ('kind = "double-beam"', 'kind = "double-beams"'),
            "[app.scene.base] kind: 'double-beams' is not allowed (did you mean double-beam?)",
        ),
        ("boom7", ('kick_axis = "base_y"', 'kick_axis = "base_yy"'), "[app] kick_axis: unknown base joint 'base_yy'"),
        (
            "trep",
            ('"path_arrows"]', '"path_arows"]'),
            "[app.scene] shown[4]: 'path_arows' is not allowed (did you mean path_arrows?)",
        ),
    ],
)
def test_a_misspelt_key_or_name_is_refused_with_its_table_and_the_nearest_known_one(
    tmp_path: Path, bundled: str, edit: tuple[str, str], expected: str
) -> None:
    assert refusal(copy_of(tmp_path, bundled, edit=edit)).startswith(expected)


def test_a_matrix_of_the_wrong_shape_is_refused_with_both_shapes(tmp_path: Path) -> None:
    path = copy_of(
        tmp_path, "boom7", edit=("  [1.06063e7, 0.0, 0.0, 0.0, 0.0, 0.0],", "  [1.06063e7, 0.0, 0.0, 0.0, 0.0],")
    )
    assert refusal(path).startswith("[base] stiffness: expected a 6 x 6 matrix, got rows of unequal length")
    rows = "\n".join(f"  [{', '.join(['1.0'] * 5)}]," for _ in range(6))
    text = (ASSETS_DIR / "boom7.toml").read_text()
    start = text.index("stiffness = [") + len("stiffness = [")
    path.write_text(text[:start] + "\n" + rows + "\n" + text[text.index("]\ndamping", start) :])
    assert refusal(path).startswith("[base] stiffness: expected a 6 x 6 matrix, got 6 x 5")
    path = copy_of(tmp_path, "trep", edit=("joint_damping = [0.0, 0.0]", "joint_damping = [0.0, 0.0, 0.0]"))
    assert refusal(path) == "[arm] joint_damping: expected 2 numbers (one per arm joint), got 3"
    path = copy_of(tmp_path, "trep", edit=("camera_position_m = [0.29, 0.47, 0.48]", "camera_position_m = [0.29]"))
    assert refusal(path) == "[app.scene] camera_position_m: expected a list of length 3, got 1"


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (
            ("stiffness = [[77.9218]]", 'stiffness = [["stiff"]]'),
            "[base] stiffness[0][0]: expected a number, got a string",
        ),
        (('joints = ["base_x"]', 'joints = "base_x"'), "[base] joints: expected a list, got a string"),
        (("kick_range_N = 5.0", 'kick_range_N = "wide"'), "[app] kick_range_N: expected a number, got a string"),
        (("trail_capacity = 150", "trail_capacity = 1.5"), "[app.scene] trail_capacity: expected an integer"),
        (("kick_duration_s = 0.1", "kick_duration_s = 0.0"), "[app] kick_duration_s: expected a number > 0.0"),
        (("stiffness = [[77.9218]]", "stiffness = [[nan]]"), "[base] stiffness[0][0]: expected a finite number"),
        (("selection = [1]", "selection = [2]"), "[base] selection[0]: 2 is not allowed (expected one of 0, 1)"),
        (("kick_peak_N = 0.8", "kick_peak_N = 8.0"), "[app] kick_peak_N: 8 N is beyond the slider's ±5 N"),
        (("[base]", "[bases]"), "[bases]: unknown table (did you mean base?)"),
    ],
)
def test_a_wrong_type_or_value_is_refused_naming_the_element(
    tmp_path: Path, edit: tuple[str, str], expected: str
) -> None:
    assert refusal(copy_of(tmp_path, "trep", edit=edit)).startswith(expected)


def test_extends_merges_tables_key_by_key_and_keeps_the_label_its_own(tmp_path: Path) -> None:
    path = tmp_path / "variant.toml"
    path.write_text(
        f'extends = "{ASSETS_DIR / "boom7.toml"}"\n[model]\nurdf = "{ASSETS_DIR / "boom7.urdf"}"\n'
        "[app]\nkick_peak_N = 2.0\n[app.gains.velocity]\ng_b_per_s = 3.0\n[app.scene]\ngrid_z_m = -1.0\n"
    )
    mine, boom7 = param_file_for(str(path)).app, param_file_for("boom7").app
    assert mine.kick_peak_N == 2.0 and mine.kick_range_N == boom7.kick_range_N  # a key of its own; boom7's
    assert mine.gains.acceleration == boom7.gains.acceleration and mine.gains.velocity.g_b_per_s == 3.0
    assert mine.scene.grid_z_m == -1.0 and mine.scene.camera_position_m == boom7.scene.camera_position_m
    assert mine.label is None and boom7.label  # listed under its own name ("file: variant.toml"), not boom7's
    assert defaults_for(str(path)).kick_axis == 1  # boom7's base_y


def test_a_chain_of_extends_is_refused_naming_both_files(tmp_path: Path) -> None:
    path = tmp_path / "chain.toml"
    path.write_text(f'extends = "{ASSETS_DIR / "boom-panda.toml"}"\n[app]\nlabel = "a chain"\n')
    message = refusal(path)
    assert "boom-panda.toml" in message and "'boom7.toml'" in message and "extends nothing" in message


def test_a_file_without_app_gets_generic_defaults(tmp_path: Path) -> None:
    text = (ASSETS_DIR / "planar3r.toml").read_text()
    (tmp_path / "planar3r.urdf").write_bytes((ASSETS_DIR / "planar3r.urdf").read_bytes())
    path = tmp_path / "plain.toml"
    path.write_text(text[: text.index("\n[app]")])
    generic, d = AppTable(), defaults_for(str(path))
    assert (d.law, d.kick_peak_N, d.kick_duration_s, d.kick_range_N, d.kick_axis) == (
        generic.law,
        generic.kick_peak_N,
        generic.kick_duration_s,
        generic.kick_range_N,
        0,
    )
    assert d.gains == {} and d.gains_for("velocity") == FALLBACK_GAINS
    assert (d.auto_exaggeration, d.target_speed_m_s) == (
        generic.scene.exaggeration == "auto",
        generic.target_speed_m_per_s,
    )
    assert d.auto_exaggeration and d.exaggeration == MANUAL_EXAGGERATION
    model = FsmsModel.from_file(path)
    style = style_for(model)
    reach = model.arm_reach
    assert style.base is None and style.grid_size == pytest.approx(4.0 * reach)  # scaled by the arm's reach
    assert presets_for(str(path)) == () and lessons_for(str(path)) == ()


def test_every_scene_key_reaches_the_drawing(tmp_path: Path) -> None:
    """Each [app.scene] length is drawn as written (its unit suffix dropped), none is ignored."""
    keys = [k for k in SceneTable.__struct_fields__ if k not in ("exaggeration", "base", "shown")]  # shown: test_stage
    values = {
        k: f"[{i + 1}.0, {i + 2}.0, {i + 3}.0]"
        if k.endswith(("position_m", "at_m", "origin_m", "label_m"))
        else str(i + 2)
        if k == "trail_capacity"
        else f"{i + 1}.5"
        for i, k in enumerate(keys)
    }
    text = (ASSETS_DIR / "trep.toml").read_text()
    start = text.index("[app.scene]")
    scene = '[app.scene]\nbase = { kind = "boom", radius_m = 0.02, sides = 5 }\n'
    scene += "".join(f"{k} = {v}\n" for k, v in values.items())
    (tmp_path / "trep.urdf").write_bytes((ASSETS_DIR / "trep.urdf").read_bytes())
    path = tmp_path / "drawn.toml"
    path.write_text(text[:start] + scene)
    style = style_for(FsmsModel.from_file(path))
    for key, value in values.items():
        drawn = getattr(style, re.sub(r"_m(_per_N)?$", "", key))
        assert drawn == (tuple(float(v) for v in value.strip("[]").split(",")) if "[" in value else float(value))
    assert (style.base.radius, style.base.sides, style.base.stations) == (0.02, 5, 25)  # stations: the default


def test_presets_and_lessons_named_in_app_must_exist(tmp_path: Path) -> None:
    path = copy_of(tmp_path, "trep", edit=('presets = ["fig10-on",', 'presets = ["fig10-onn",'))
    load_spec(path)  # a name is checked where the registry is: the app refuses the file at start
    with pytest.raises(
        ModelFileError, match=r"\[app\] presets: unknown preset 'fig10-onn' \(did you mean fig10-on\?\)"
    ):
        presets_for(str(path))
    path = copy_of(tmp_path, "trep", edit=('"trep-spring"', '"trep-sprung"'))
    with pytest.raises(
        ModelFileError, match=r"\[app\] lessons: unknown lesson 'trep-sprung' \(did you mean trep-spring\?\)"
    ):
        lessons_for(str(path))


def test_the_bundled_models_are_the_files_with_an_app_table_in_menu_order(tmp_path: Path) -> None:
    assert MODEL_NAMES == ("trep", "planar3r", "boom7", "trep2", "boom-panda")
    copy_of(tmp_path, "trep", name="second", edit=("menu_order = 1", "menu_order = 7"))
    copy_of(tmp_path, "planar3r", name="first")
    text = (tmp_path / "second.toml").read_text()
    (tmp_path / "no_app.toml").write_text(text[: text.index("\n[app]")])
    assert _bundled(tmp_path) == ("first", "second")


@pytest.mark.parametrize(
    "compensating",
    ["compensating = []", 'compensating = [["c_joint1", "c_joint2"], []]', 'compensating = ["c_joint1", ["c_joint2"]]'],
)
def test_arms_without_joints_are_refused(tmp_path: Path, compensating: str) -> None:
    path = copy_of(tmp_path, "trep2", edit=('compensating = ["c_joint1", "c_joint2"]', compensating))
    expected = "[arms] task and compensating: expected a non-empty list of joint names (or of such lists)"
    assert refusal(path) == expected
