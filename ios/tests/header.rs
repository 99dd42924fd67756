//! The checked-in C header is what cbindgen makes from the current `src/ffi.rs`: a stale header
//! fails here. `cargo xtask header` (or `PHANTOGRAM_BLESS=1`) rewrites it.

use std::path::Path;

#[test]
fn checked_in_header_matches_the_abi() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).expect("cbindgen.toml parses");
    let bindings = cbindgen::Builder::new()
        .with_crate(crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header");
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    let generated = String::from_utf8(generated).expect("the header is UTF-8");
    for symbol in [
        "pg_engine_create",
        "pg_draw",
        "pg_read_frame",
        "PG_STATUS_PANIC",
        "PgConfig",
    ] {
        assert!(generated.contains(symbol), "{symbol} missing from the generated header");
    }
    let path = crate_dir.join("include/phantogram.h");
    if std::env::var_os("PHANTOGRAM_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("writing the header");
        return;
    }
    let checked_in = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        checked_in == generated,
        "{} is stale: the C ABI changed; run `cargo xtask header` and commit the result",
        path.display()
    );
}
