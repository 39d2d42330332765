fn main() {
    std::process::exit(fabkit::cli::main());
}
