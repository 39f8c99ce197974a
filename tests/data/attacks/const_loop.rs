/// A constant the compiler evaluates for a very long time (about 10¹⁰ steps).
#[allow(long_running_const_eval)]
const SPIN: u64 = {
    let mut i = 0u64;
    let mut x = 0u64;
    while i < 10_000_000_000 {
        x = x.wrapping_add(i ^ (x >> 3));
        i += 1;
    }
    x
};

fn attack(_center: Vec3, _radius: f32) {
    println!("spin {SPIN}");
}
