"""The measured-input estimator: the steady state back from its own feedback voltage, the
layout of its output, what it cannot estimate from."""
import numpy as np
import pytest

import trum


def test_estimate_of_the_solved_feedback_voltage_is_the_steady_state():
    m = trum.Motor("generic60")
    pre = np.array([150.0, 250.0, 350.0, 250.0])
    tq = np.array([0.0, 0.1, 0.2, 0.3])
    res = m.solve(preload_n=pre, torque_nm=tq, voltage_v=200.0, frequency_hz=43e3)
    data = {"preload_n": pre, "voltage_v": np.full(4, 200.0), "frequency_hz": np.full(4, 43e3), "torque_nm": tq,
            "feedback_v": res.feedback_v, "speed_rpm": res.speed_rpm + 1.0}
    est = trum.estimate(m, data)
    assert est["status"].tolist() == ["ok"] * 4
    for q in ("amplitude_m", "contact_angle_deg", "driving_angle_deg", "friction_loss_w", "efficiency"):
        np.testing.assert_allclose(est[q], getattr(res, q), rtol=1e-6, atol=1e-12, err_msg=q)
    np.testing.assert_allclose(est["input_power_w"], res.input_power_w, rtol=1e-5)
    np.testing.assert_allclose(est["speed_residual_rpm"], 1.0, rtol=1e-6)
    assert (est["driving_length_m"] <= est["contact_length_m"]).all()
    assert [c[0] for c in trum.ESTIMATE_COLUMNS][-1] == "efficiency"
    # a DataFrame in, a DataFrame out, with the same index
    pd = pytest.importorskip("pandas")
    df = pd.DataFrame(data, index=[10, 11, 12, 13])
    out = trum.estimate("generic60", df)
    assert isinstance(out, pd.DataFrame) and list(out.index) == [10, 11, 12, 13]
    np.testing.assert_array_equal(out["efficiency"].to_numpy(), est["efficiency"])
    assert "measured_speed_rpm" in out and "warnings" in out


def test_estimate_statuses_and_errors():
    m = trum.Motor("generic60")
    data = {"preload_n": [250.0, 250.0, 250.0, -1.0], "voltage_v": [200.0] * 4, "frequency_hz": [43e3] * 4,
            "torque_nm": [0.1, 0.1, 50.0, 0.1], "feedback_v": [np.nan, 0.0, 40.0, 40.0]}
    est = trum.estimate(m, data)
    assert est["status"].tolist() == ["no_feedback", "no_contact_state", "stall", "invalid_input"]
    assert np.isnan(est["efficiency"][[0, 1, 3]]).all() and est["efficiency"][2] == 0.0
    with pytest.raises(trum.InputError, match="no column 'feedback_v'"):
        trum.estimate(m, {k: v for k, v in data.items() if k != "feedback_v"})
    with pytest.raises(trum.InputError, match="has 2 rows, expected 4"):
        trum.estimate(m, {**data, "feedback_v": [1.0, 2.0]})
    with pytest.raises(trum.InputError, match="feedback_gain_v_per_m"):
        trum.estimate(m.with_params({"electrical.feedback_gain_v_per_m": 0.0}), data)
