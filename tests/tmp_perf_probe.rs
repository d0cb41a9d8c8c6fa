#[test]
fn probe() {
    let t = std::time::Instant::now();
    let r = chain_core::load_file(std::path::Path::new("/tmp/big.yaml"));
    eprintln!("{:?} {}", t.elapsed(), r.map(|m| m.errors.len()).unwrap_or_else(|d| { eprintln!("{d}"); 0 }));
}
