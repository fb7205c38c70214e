//! The solver tables of README.md and docs/cli.md are the registry's (`mbd solvers
//! --markdown`), so a solver added to the registry cannot be missing from them.

mod common;

/// The text between `<!-- solvers:begin -->` and `<!-- solvers:end -->` of a file.
fn table_in(path: &str) -> String {
    let text = std::fs::read_to_string(format!("{}/{path}", common::repo().display()))
        .unwrap_or_else(|e| panic!("{path}: {e}"));
    let begin = "<!-- solvers:begin -->\n";
    let i = text
        .find(begin)
        .unwrap_or_else(|| panic!("{path}: no {begin}"))
        + begin.len();
    let j = text[i..]
        .find("<!-- solvers:end -->")
        .unwrap_or_else(|| panic!("{path}: no end marker"));
    text[i..i + j].to_string()
}

#[test]
fn readme_and_cli_docs_carry_the_registry_table() {
    let want = mbd::registry().markdown_table();
    for path in ["README.md", "docs/cli.md"] {
        assert_eq!(
            table_in(path),
            want,
            "{path}: the solver table differs from the registry; regenerate it with \
             `cargo run -p mbd-cli -- solvers --markdown`"
        );
    }
}
