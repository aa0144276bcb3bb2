//! Nothing to build: the build-dependency in Cargo.toml only aligns syn's
//! features with the Python wheel's build (see there).

fn main() {}
