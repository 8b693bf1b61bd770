"""transition_strip.py: each transition's middle frame, cropped to what any of them draws, side by side; a folder
without the dumps is refused."""
import sys
from pathlib import Path

from PIL import Image

SCRIPTS = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(SCRIPTS))
import transition_strip  # noqa: E402


def test_middle_frames_cropped_side_by_side(tmp_path):
    (tmp_path / "frames").mkdir()
    (tmp_path / "transitions.csv").write_text(
        "scene,method,count,transition,first_frame,last_frame\n"
        "s,geomorph,1,0,4,8\ns,discrete,1,0,4,8\ns,geomorph,1,1,20,21\n")
    for frame, x in ((6, 10), (20, 30)):
        im = Image.new("RGB", (64, 48), (60, 63, 69))
        im.paste((200, 10, 10), (x, 20, x + 5, 25))
        im.save(tmp_path / "frames" / f"s_geomorph_c1_f{frame:05d}_method.png")
    out = tmp_path / "strip.png"
    assert transition_strip.main([str(tmp_path), "geomorph", str(out)]) == 0
    strip = Image.open(out)
    # The box both draw: x 10..35, y 20..25, 4 pixels around (x 6..39, y 16..29): 33 x 13, two tiles, twice the size.
    assert strip.size == (2 * 2 * 33, 2 * 13)
    assert strip.getpixel((2 * 6, 2 * 6)) == (200, 10, 10)


def test_a_folder_without_dumps_is_refused(tmp_path, capsys):
    (tmp_path / "transitions.csv").write_text(
        "scene,method,count,transition,first_frame,last_frame\ns,geomorph,1,0,4,8\n")
    assert transition_strip.main([str(tmp_path), "geomorph", str(tmp_path / "o.png")]) == 2
    assert "--dump-frames --dump-transitions" in capsys.readouterr().err
    assert transition_strip.main([str(tmp_path), "alpha", str(tmp_path / "o.png")]) == 2
