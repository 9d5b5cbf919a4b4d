fn main() {
    println!("tesela: under construction");
}
