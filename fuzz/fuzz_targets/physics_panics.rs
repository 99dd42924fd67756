//! The panic hook of the targets that drive the whole engine (`c_abi`, `jni`; shared with
//! `#[path]`).

/// libFuzzer's panic hook aborts on every panic, even one the code catches. The Diorama catches a
/// panic inside rapier/parry (parry's EPA indexes out of bounds on some degenerate contacts;
/// `Diorama::faults` counts them) and rebuilds its world, by design: such a panic is let through
/// here, so that the run goes on to find what is not handled. Every other panic still aborts, and
/// so does a physics panic that escapes the Diorama: the call then reports a panic through its
/// bridge, which the call sequence rejects with a panic of its own.
pub fn tolerate() {
    let libfuzzer_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let in_physics = info
            .location()
            .is_some_and(|l| l.file().contains("/parry3d-") || l.file().contains("/rapier3d-"));
        if in_physics {
            eprintln!("tolerated (the Diorama recovers): {info}");
        } else {
            libfuzzer_hook(info);
        }
    }));
}
