fn main() {
    let p = std::env::args().nth(1).unwrap();
    let t = std::fs::read_to_string(&p).unwrap();
    match trum_core::Motor::from_toml_str_with_sweep(&t, &p) {
        Ok((m, s)) => {
            println!("{}", m.to_toml());
            println!("{s:?}");
            let back = trum_core::Motor::from_toml_str(&m.to_toml(), "x").unwrap();
            assert_eq!(back, m);
        }
        Err(e) => println!("ERR {e}"),
    }
}
