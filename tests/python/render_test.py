# exotwin.render_frame (python/module_render.cc; the rendering plugin's RenderStill): a still of the
# leg off-screen into a numpy array; the pose shows in the pixels; bad sizes and angles are InputError.
import numpy as np
import pytest

import exotwin


def test_a_still_of_the_leg():
    a = exotwin.render_frame(0.3, -0.6, width=320, height=240)
    assert a.shape == (240, 320, 3) and a.dtype == np.uint8
    assert a.std() > 5  # not a blank frame
    b = exotwin.render_frame(0.3, -0.6, width=320, height=240)
    assert np.array_equal(a, b)  # the same pose, the same pixels
    c = exotwin.render_frame(1.2, -1.5, width=320, height=240)
    assert np.mean(a != c) > 0.01  # another pose, another picture
    s1 = exotwin.render_frame(0.3, -0.6, params=exotwin.data_path("examples/S1.yaml"), width=320, height=240)
    assert np.array_equal(s1, a)  # the default model is S1's


def test_ghost_legs():
    a = exotwin.render_frame(0.3, -0.6, width=320, height=240)
    g = exotwin.render_frame(0.3, -0.6, ghosts=[(1.0, -1.4)], width=320, height=240)
    changed = np.any(a != g, axis=2)
    assert changed.mean() > 0.005  # the ghost shows
    px = g[changed].astype(float)
    assert px[:, 0].mean() > px[:, 1].mean() + 20  # translucent red by default
    green = exotwin.render_frame(0.3, -0.6, ghosts=[(1.0, -1.4)], ghost_rgba=[(0.1, 0.9, 0.1, 0.5)],
                                 width=320, height=240)
    px = green[np.any(a != green, axis=2)].astype(float)
    assert px[:, 1].mean() > px[:, 0].mean() + 10  # the colour given (the ground shows through: less than red alone)
    two = exotwin.render_frame(0.3, -0.6, ghosts=[(1.0, -1.4), (0.0, -0.2)], width=320, height=240)
    assert np.any(np.any(two != g, axis=2))
    with pytest.raises(exotwin.InputError, match="one colour per ghost"):
        exotwin.render_frame(0, 0, ghosts=[(0, 0)], ghost_rgba=[(1, 0, 0, 1), (0, 1, 0, 1)])
    with pytest.raises(exotwin.InputError, match="ghosts: expected"):
        exotwin.render_frame(0, 0, ghosts=[1.0])
    with pytest.raises(exotwin.InputError, match="ghost 0"):
        exotwin.render_frame(0, 0, ghosts=[(float("inf"), 0)])


def test_bad_requests():
    with pytest.raises(exotwin.InputError, match="even width and height"):
        exotwin.render_frame(0, 0, width=321, height=240)
    with pytest.raises(exotwin.InputError, match="finite angles"):
        exotwin.render_frame(float("nan"), 0)
    with pytest.raises(exotwin.InputError, match="no_such.yaml"):
        exotwin.render_frame(0, 0, params="no_such.yaml")
