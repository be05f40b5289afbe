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


def test_bad_requests():
    with pytest.raises(exotwin.InputError, match="even width and height"):
        exotwin.render_frame(0, 0, width=321, height=240)
    with pytest.raises(exotwin.InputError, match="finite angles"):
        exotwin.render_frame(float("nan"), 0)
    with pytest.raises(exotwin.InputError, match="no_such.yaml"):
        exotwin.render_frame(0, 0, params="no_such.yaml")
