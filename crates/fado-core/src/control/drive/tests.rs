/// The stall band's default torque ratio is what its documentation derives it from: the
/// torque deficit 1 − cos δ of an estimate δ = 0.25 rad off.
#[test]
fn stall_torque_band_default_is_the_deficit_of_the_clean_threshold() {
    let deficit = 1.0 - nalgebra::ComplexField::cos(0.25_f64);
    assert!((super::STALL_TORQUE_BAND_RATIO - deficit).abs() < 1e-16);
}
