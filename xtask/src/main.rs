fn main() { println!("xtask args: {:?}", std::env::args().skip(1).collect::<Vec<_>>()); }
