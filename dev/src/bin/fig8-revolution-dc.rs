//! Diagnostic: prints every evaluated fig8 revolution (end time, |DC(λ2 − λs)| / λf) and the
//! worst one, optionally with a TOML override given as the first argument.
fn main() {
    let toml = std::env::args()
        .nth(1)
        .map(|p| std::fs::read_to_string(p).unwrap());
    let scen = std::env::args().nth(2).unwrap_or_else(|| "fig8".into());
    let o = fado_sim::scenario::simulate(&scen, toml.as_deref(), false, None).unwrap();
    let lf = o.config.motor.flux_linkage;
    for (t, dc) in &o.probe.revolutions {
        println!("{t:8.4} {:7.4}", dc / lf);
    }
    for c in &o.checks {
        println!("{} = {:.4} {}", c.name, c.value, c.passed);
    }
    println!(
        "max err {:.4} near0 {:.4}",
        o.metrics.max_angle_error, o.metrics.max_angle_error_zero_speed
    );
}
