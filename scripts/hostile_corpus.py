"""Write the hostile case-file corpus of ``tests/data/hostile/`` (run from the project root).

Each file is a case an outside user could hand to pressplan to hurt it: YAML that costs memory or
recursion, duplicate keys, numbers that overflow arithmetic, values outside every sensible range,
encodings, degenerate-but-valid-looking sizes. Every one must end in exit 2 with one line naming the
file (and the field where there is one), quickly and without a traceback; ``# expect:`` gives a part
of that line. ``tests/data/number_forms/`` holds valid cases whose numbers are written in every form
an engineer uses; they must load.
"""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BASE = (ROOT / "cases" / "wang2023-side-panel.yaml").read_text(encoding="utf-8")
BASE = BASE[: BASE.index("published:")]  # the case without the source's numbers


LINK_DRIVE = (ROOT / "cases" / "link-drive-side-panel.yaml").read_text(encoding="utf-8")
KNUCKLE_JOINT = (ROOT / "cases" / "knuckle-joint-coining.yaml").read_text(encoding="utf-8")


def edited(text: str, old: str, new: str) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


def replace(old: str, new: str) -> str:
    assert old in BASE, old
    return BASE.replace(old, new, 1)


def field(path: str, value: str) -> str:
    """The base case with the dotted field set to the YAML text ``value`` (the key must exist)."""
    section, key = path.split(".")
    lines = BASE.splitlines()
    inside = False
    for i, line in enumerate(lines):
        if line.startswith(f"{section}:"):
            inside = True
        elif inside and line.strip().startswith(f"{key}:"):
            indent = line[: len(line) - len(line.lstrip())]
            lines[i] = f"{indent}{key}: {value}"
            return "\n".join(lines) + "\n"
    raise KeyError(path)


def add(path: str, value: str) -> str:
    """The base case with ``section.key: value`` added."""
    section, key = path.split(".")
    text = BASE if f"\n{section}:" in "\n" + BASE else BASE + f"{section}:\n"
    lines = text.splitlines()
    i = next(k for k, line in enumerate(lines) if line.startswith(f"{section}:"))
    lines.insert(i + 1, f"  {key}: {value}")
    return "\n".join(lines) + "\n"


PUBLISHED = """published:
  solution:
    x1_s: 0.9
    x2_s: 1.3
    x3_s: 3.24
    x4_s: 4.14
    x5_s: 5.14
    wm1_rpm: 22.5
    wm2_rpm: 24.5
    T1_s: 0.1
    T5_s: 0.11
    T9_s: 1.4
    T10_s: 0.125
    T14_s: 0.1
    J_rpm_s2: 313.63
"""


def published(key: str, value: str) -> str:
    text = PUBLISHED.replace(f"    {key}: ", f"    {key}: {value} #", 1)
    return BASE + text


def bomb(levels: int = 9) -> str:
    lines = ['a0: &a0 ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]']
    for k in range(1, levels):
        refs = ",".join([f"*a{k - 1}"] * 9)
        lines.append(f"a{k}: &a{k} [{refs}]")
    return "\n".join(lines) + "\n"


CORPUS: dict[str, tuple[str, str | bytes]] = {
    # YAML that costs memory, recursion or time
    "alias_bomb": ("aliases", bomb()),
    "alias_bomb_in_case": ("aliases", BASE + "title_extra: &x [1, 2]\nmore: *x\n"),
    "alias_one": ("aliases", replace("name: wang2023-side-panel", "name: &n wang\ntitle: *n")),
    "merge_key_alias": ("aliases", BASE + "defaults: &d {a: 1}\nother:\n  <<: *d\n"),
    "nested_brackets": ("nested more than", "[" * 2000 + "]" * 2000 + "\n"),
    "nested_braces": ("nested more than", "a: " + "{b: " * 500 + "1" + "}" * 500 + "\n"),
    "nested_block_mappings": (
        "nested more than",
        "".join(f"{'  ' * i}k{i}:\n" for i in range(40)) + "  " * 40 + "x: 1\n",
    ),
    "nested_lists": ("nested more than", "".join(f"{'  ' * i}- \n" for i in range(40)) + "  " * 40 + "- 1\n"),
    "many_values": ("more than", "values: [" + ",".join(["1"] * 6000) + "]\n"),
    "many_keys": ("more than", "".join(f"k{i}: {i}\n" for i in range(6000))),
    "too_large": ("too large", BASE + "# " + "x" * 300_000 + "\n"),
    "long_line_title": ("title", replace("title: Side-panel", "title: " + "x" * 5000 + " Side-panel")),
    # duplicate keys
    "duplicate_top_key": ("limits: duplicate key", BASE + "limits:\n  slider_accel_mm_s2: 1\n"),
    "duplicate_nested_key": (
        "process.transfer_time_s: duplicate key",
        replace("  transfer_time_s: 2.0", "  transfer_time_s: 2.0\n  transfer_time_s: 0.5"),
    ),
    "duplicate_limit_key": (
        "limits.slider_accel_mm_s2: duplicate key",
        replace("  slider_accel_mm_s2: 3500", "  slider_accel_mm_s2: 3500\n  slider_accel_mm_s2: 99999"),
    ),
    "duplicate_name": ("name: duplicate key", "name: a\n" + BASE),
    "duplicate_in_flow": (
        "press.crank_radius_mm: duplicate key",
        replace(
            "press:\n  crank_radius_mm: 450\n  rod_length_mm: 1200",
            "press: {crank_radius_mm: 450, crank_radius_mm: 45, rod_length_mm: 1200}",
        ),
    ),
    # tags and types YAML must not build
    "python_object_tag": ("could not determine a constructor", BASE + "x: !!python/object/apply:os.system ['true']\n"),
    "python_name_tag": ("could not determine a constructor", BASE + "x: !!python/name:os.system\n"),
    "custom_tag": ("could not determine a constructor", field("press.crank_radius_mm", "!meters 0.45")),
    "binary_tag": ("press.crank_radius_mm", field("press.crank_radius_mm", "!!binary aGVsbG8=")),
    "set_value": ("press.crank_radius_mm", field("press.crank_radius_mm", "!!set {450}")),
    "timestamp_value": ("process.transfer_time_s", field("process.transfer_time_s", "2001-12-14")),
    "complex_key": ("unhashable key", "? [a, b]\n: 1\n"),
    "int_key_top": ("1", BASE + "1: 2\n"),
    "null_key": ("None", BASE + "~: 2\n"),
    # documents, encodings, bytes
    "two_documents": ("YAML syntax error", BASE + "---\nname: other\n"),
    "document_end_only": ("empty", "---\n...\n"),
    "scalar_top": ("expected a mapping", "450\n"),
    "string_top": ("expected a mapping", "just a sentence\n"),
    "utf16": ("binary", BASE.encode("utf-16")),
    "latin1": ("not UTF-8", BASE.replace("Wang, Wu", "Wäng, Wu").encode("latin-1")),
    "nul_byte": ("binary", BASE.encode() + b"\x00\n"),
    "random_bytes": ("binary", bytes(range(256)) * 4),
    "control_chars": ("YAML syntax error", BASE + "title2: \x07\x08\n"),
    "tab_indent": ("YAML syntax error", BASE.replace("  crank_radius_mm", "\tcrank_radius_mm", 1)),
    "unclosed_quote": ("YAML syntax error", replace("name: wang2023-side-panel", 'name: "wang')),
    "unclosed_bracket": (
        "YAML syntax error",
        replace("press:\n  crank_radius_mm: 450", "press: [crank_radius_mm: 450"),
    ),
    # numbers that overflow or are not finite
    "radius_1e200": ("press.crank_radius_mm", field("press.crank_radius_mm", "1e200")),
    "lengths_1e308": (
        "press.crank_radius_mm",
        field("press.crank_radius_mm", "1e308").replace("rod_length_mm: 1200", "rod_length_mm: 1.7e308"),
    ),
    "rod_1e308": ("press.rod_length_mm", field("press.rod_length_mm", "1e308")),
    "radius_1e400": ("press.crank_radius_mm", field("press.crank_radius_mm", "1e400")),
    "radius_huge_int": ("press.crank_radius_mm", field("press.crank_radius_mm", "1" + "0" * 400)),
    "radius_tiny": ("press.crank_radius_mm", field("press.crank_radius_mm", "1e-300")),
    "radius_negative_huge": ("press.crank_radius_mm", field("press.crank_radius_mm", "-1e308")),
    "radius_inf": ("press.crank_radius_mm", field("press.crank_radius_mm", ".inf")),
    "radius_nan": ("press.crank_radius_mm", field("press.crank_radius_mm", ".nan")),
    "accel_tiny": ("limits.slider_accel_mm_s2", field("limits.slider_accel_mm_s2", "1e-300")),
    "accel_huge": ("limits.slider_accel_mm_s2", field("limits.slider_accel_mm_s2", "1e300")),
    "transfer_time_huge": ("process.transfer_time_s", field("process.transfer_time_s", "1e300")),
    "transfer_time_tiny": ("process.transfer_time_s", field("process.transfer_time_s", "1e-300")),
    "draw_speed_tiny": ("process.draw_speed_rpm", field("process.draw_speed_rpm", "1e-9")),
    "draw_speed_huge": ("process.draw_speed_rpm", field("process.draw_speed_rpm", "1e300")),
    "min_crank_speed_tiny": ("limits.min_crank_speed_rpm", add("limits.min_crank_speed_rpm", "1e-12")),
    "min_crank_speed_huge": ("limits.min_crank_speed_rpm", add("limits.min_crank_speed_rpm", "1e300")),
    "die_speed_tiny": ("limits.die_speed_mm_s", field("limits.die_speed_mm_s", "1e-300")),
    "draw_start_speed_huge": ("limits.draw_start_speed_mm_s", field("limits.draw_start_speed_mm_s", "1e300")),
    "crank_jerk_huge": ("limits.crank_jerk_rad_s3", add("limits.crank_jerk_rad_s3", "1e300")),
    "crank_accel_tiny": ("limits.crank_accel_rad_s2", add("limits.crank_accel_rad_s2", "1e-300")),
    "crank_speed_huge": ("limits.crank_speed_rpm", add("limits.crank_speed_rpm", "1e300")),
    "safety_height_huge": ("process.safety_height_mm", field("process.safety_height_mm", "1e300")),
    "die_height_huge": ("limits.die_height_mm", field("limits.die_height_mm", "1e300")),
    "law_parameter_huge": (
        "planner.law_parameter",
        BASE.replace("  motion_law: improved-s-curve", "  motion_law: seven-segment\n  law_parameter: 1e300"),
    ),
    "angle_huge": ("key_points.closing_deg", field("key_points.closing_deg", "1e300")),
    # a hold at the bottom (docs/modes.md): the published draw ends past BDC, where a hold at BDC cannot follow it
    "hold_time_zero": ("process.hold_time_s", add("process.hold_time_s", "0")),
    "hold_time_huge": ("process.hold_time_s", add("process.hold_time_s", "1e300")),
    "hold_time_word": ("process.hold_time_s", add("process.hold_time_s", "long")),
    "hold_after_the_draw_end": ("key_points.draw_end_deg", add("process.hold_time_s", "0.3")),
    "hold_height_alone": ("process.hold_height_mm", add("process.hold_height_mm", "5")),
    "hold_height_nan": ("process.hold_height_mm", add("process.hold_height_mm", ".nan")),
    # a draw at constant slide speed: the published case gives a constant draw speed too
    "slide_speed_with_draw_speed": ("process.draw_speed_rpm", add("process.draw_slide_speed_mm_s", "60")),
    "slide_speed_negative": ("process.draw_slide_speed_mm_s", add("process.draw_slide_speed_mm_s", "-60")),
    # a pendulum stroke: a mode that is no mode; a swing under the optimal law (not yet)
    "mode_word": ("planner.mode", add("planner.mode", "swing")),
    "pendulum_optimal": (
        "planner.motion_law",
        BASE.replace("  motion_law: improved-s-curve", "  motion_law: optimal\n  mode: pendulum"),
    ),
    "angle_inf": ("key_points.opening_deg", field("key_points.opening_deg", "-.inf")),
    # types an engineer might not mean
    "bool_number": ("press.crank_radius_mm", field("press.crank_radius_mm", "true")),
    "yes_number": ("press.crank_radius_mm", field("press.crank_radius_mm", "yes")),
    "null_required": ("press.crank_radius_mm", field("press.crank_radius_mm", "~")),
    "list_number": ("press.crank_radius_mm", field("press.crank_radius_mm", "[450]")),
    "mapping_number": ("press.crank_radius_mm", field("press.crank_radius_mm", "{mm: 450}")),
    "string_with_unit": ("press.crank_radius_mm", field("press.crank_radius_mm", "450 mm")),
    "comma_decimal": ("process.transfer_time_s", field("process.transfer_time_s", "2,0")),
    "sexagesimal": ("process.transfer_time_s", field("process.transfer_time_s", "1:30")),
    "octal_looking": ("press.crank_radius_mm", field("press.crank_radius_mm", "0450")),
    "name_list": ("name", replace("name: wang2023-side-panel", "name: [a, b]")),
    "name_too_long": ("name", replace("name: wang2023-side-panel", "name: " + "n" * 500)),
    "name_path": ("never", replace("name: wang2023-side-panel", "name: ../../etc/passwd\nnever: 1")),
    "law_as_number": ("planner.motion_law", field("planner.motion_law", "7")),
    "section_as_list": ("limits", BASE[: BASE.index("limits:")] + "limits: [1, 2]\n" + BASE[BASE.index("planner:") :]),
    "section_as_string": ("press", replace("press:\n  crank_radius_mm: 450\n  rod_length_mm: 1200", "press: big")),
    # the source's block: values that would break the writers after the solve
    "published_T1_zero": ("published.solution.T1_s", published("T1_s", "0")),
    "published_T14_negative": ("published.solution.T14_s", published("T14_s", "-0.1")),
    "published_period_absurd": ("published.solution.x5_s", published("x5_s", "1e12")),
    "published_speed_zero": ("published.solution.wm1_rpm", published("wm1_rpm", "0")),
    "published_jerk_huge": ("published.solution.J_rpm_s2", published("J_rpm_s2", "1e300")),
    "published_spm_inf": ("published.spm", BASE + "published:\n  spm: .inf\n"),
    "published_height_huge": (
        "published.key_points.closing.height_mm",
        BASE + "published:\n  key_points:\n    closing: {height_mm: 1e300}\n",
    ),
    # linkages: links that cannot close, a pivot inside the crank circle, a slide that turns back, sections
    "link_drive_cannot_close": ("press.link_drive.rocker_mm", edited(LINK_DRIVE, "rocker_mm: 810", "rocker_mm: 200")),
    "link_drive_pivot_inside_crank": (
        "press.link_drive.rocker_pivot_x_mm",
        edited(
            edited(LINK_DRIVE, "rocker_pivot_x_mm: 1060", "rocker_pivot_x_mm: 100"),
            "rocker_pivot_y_mm: 340",
            "rocker_pivot_y_mm: 100",
        ),
    ),
    "link_drive_negative_length": (
        "press.link_drive.ternary_rod_side_mm",
        edited(LINK_DRIVE, "ternary_rod_side_mm: 1060", "ternary_rod_side_mm: -1060"),
    ),
    "link_drive_huge_rod": (
        "press.link_drive.rod_length_mm",
        edited(LINK_DRIVE, "rod_length_mm: 1060", "rod_length_mm: 1e308"),
    ),
    "link_drive_nan_angle": (
        "press.link_drive.ternary_angle_deg",
        edited(LINK_DRIVE, "ternary_angle_deg: 134", "ternary_angle_deg: .nan"),
    ),
    "link_drive_turns_back": (
        "press.link_drive:",
        edited(LINK_DRIVE, "rocker_pivot_x_mm: 1060", "rocker_pivot_x_mm: 100"),
    ),
    "link_drive_rod_mass": ("drive.rod_mass_kg", edited(LINK_DRIVE, "  links:", "  rod_mass_kg: 2000\n  links:")),
    "knuckle_joint_cannot_close": (
        "press.knuckle_joint.main_rod_mm",
        edited(KNUCKLE_JOINT, "main_rod_mm: 910", "main_rod_mm: 300"),
    ),
    "knuckle_joint_turns_back": (
        "press.knuckle_joint:",
        edited(KNUCKLE_JOINT, "slide_offset_mm: 0 ", "slide_offset_mm: 700 "),
    ),
    "knuckle_joint_without_section": (
        "press.knuckle_joint: is required",
        KNUCKLE_JOINT[: KNUCKLE_JOINT.index("  knuckle_joint:")] + KNUCKLE_JOINT[KNUCKLE_JOINT.index("key_points:") :],
    ),
    "knuckle_joint_unknown_link": ("drive.links.ternary", edited(KNUCKLE_JOINT, "    rocker: {", "    ternary: {")),
    "mechanism_unknown": ("press.mechanism", replace("press:\n", "press:\n  mechanism: toggle\n")),
    "linkage_section_on_a_crank_slider": (
        "press.link_drive: belongs to another mechanism",
        replace(
            "press:\n",
            "press:\n  link_drive: {crank_radius_mm: 200, ternary_rocker_side_mm: 700, rocker_mm: 800, "
            "rocker_pivot_x_mm: 1000, rocker_pivot_y_mm: 300, ternary_angle_deg: 134, ternary_rod_side_mm: 1000, "
            "rod_length_mm: 1000}\n",
        ),
    ),
}

NUMBER_FORMS = {  # valid cases: every form an engineer writes a number in
    "exponent_no_sign": field("limits.slider_accel_mm_s2", "3.5e3"),
    "exponent_no_dot": field("process.transfer_time_s", "20e-1"),
    "exponent_upper": field("limits.slider_accel_mm_s2", "3.5E+3"),
    "exponent_int": field("press.crank_radius_mm", "45e1"),
    "leading_dot": field("process.transfer_time_s", "2.0").replace("die_height_mm: 10", "die_height_mm: .1e2"),
    "trailing_dot": field("press.crank_radius_mm", "450."),
    "underscore": field("limits.slider_accel_mm_s2", "3_500"),
    "plus_sign": field("press.rod_length_mm", "+1200"),
    "small_exponent": field("limits.die_height_mm", "1e1"),
    "integer_float": field("process.draw_speed_rpm", "6.70"),
}


def main() -> None:
    hostile = ROOT / "tests" / "data" / "hostile"
    forms = ROOT / "tests" / "data" / "number_forms"
    for folder in (hostile, forms):
        folder.mkdir(parents=True, exist_ok=True)
        for old in folder.glob("*.yaml"):
            old.unlink()
    for name, (expect, body) in CORPUS.items():
        data = body if isinstance(body, bytes) else body.encode("utf-8")
        (hostile / f"{name}.yaml").write_bytes(data)
        (hostile / f"{name}.expect").write_text(expect + "\n", encoding="utf-8")
    for name, body in NUMBER_FORMS.items():
        (forms / f"{name}.yaml").write_text(body, encoding="utf-8")
    print(f"{len(CORPUS)} hostile files, {len(NUMBER_FORMS)} number forms")


if __name__ == "__main__":
    main()
