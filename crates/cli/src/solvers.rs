//! `mbd solvers`: the registry's solvers as a text table.

/// The registered solvers, one row each: spec string, order, whether `--tol` works, whether
/// the cost per step is O(N), what it refuses; the description on the line below.
pub fn table() -> String {
    let reg = mbd::registry();
    let rows: Vec<[String; 5]> = reg
        .variants()
        .map(|(_, v)| {
            [
                v.spec.to_string(),
                v.order.to_string(),
                if v.adaptive { "yes" } else { "no" }.to_string(),
                if v.scales { "yes" } else { "no" }.to_string(),
                if v.refuses.is_empty() { "-" } else { v.refuses }.to_string(),
            ]
        })
        .collect();
    let head = ["solver", "order", "--tol", "O(N)", "refuses"];
    let mut width = head.map(str::len);
    for r in &rows {
        for (w, c) in width.iter_mut().zip(r) {
            *w = (*w).max(c.len());
        }
    }
    let line = |cells: [&str; 5]| -> String {
        let mut s = String::new();
        for (i, (c, w)) in cells.iter().zip(width).enumerate() {
            if i + 1 == cells.len() {
                s.push_str(c);
            } else {
                s.push_str(&format!("{c:<w$}  "));
            }
        }
        s.trim_end().to_string() + "\n"
    };
    let mut out = line(head);
    for ((_, v), r) in reg.variants().zip(&rows) {
        out.push_str(&line([&r[0], &r[1], &r[2], &r[3], &r[4]]));
        out.push_str(&format!("    {}\n", v.description));
    }
    out.push_str(&format!(
        "\nSpec syntax: {}\n--tol works with the solvers marked yes; every solver takes --h.\n",
        reg.syntax_list()
    ));
    out
}
