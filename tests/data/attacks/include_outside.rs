/// A file from outside the crate compiled in (a secret of the instructor's machine).
const LEAK: &str = include_str!("@SECRET@");

fn attack(_center: Vec3, _radius: f32) {
    println!("leaked: {LEAK}");
}
