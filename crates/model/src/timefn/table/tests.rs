use super::*;
use crate::timefn::TimeFunction;
use std::f64::consts::PI;

/// `n` samples of `sin` on `[0, pi]` (where its second derivative vanishes at both ends, so the
/// natural end condition is exact to the order of the spline).
fn sine_table(n: usize, interpolation: Interpolation) -> Table {
    let t: Vec<f64> = (0..n).map(|i| PI * i as f64 / (n - 1) as f64).collect();
    let y = t.iter().map(|t| t.sin()).collect();
    Table::new(t, y, interpolation).unwrap()
}

/// Largest error of value, first and second derivative against sin on a fine grid.
fn sine_errors(table: &Table) -> [f64; 3] {
    let mut e = [0.0f64; 3];
    for k in 0..=1000 {
        let t = PI * k as f64 / 1000.0;
        let got = table.eval(t);
        let want = [t.sin(), t.cos(), -t.sin()];
        for i in 0..3 {
            e[i] = e[i].max((got[i] - want[i]).abs());
        }
    }
    e
}

/// Halving the sample spacing divides the spline's error by 2^4 in the value, 2^3 in the
/// first and 2^2 in the second derivative (measured orders within 0.3); linear interpolation
/// is of order 2 in the value.
#[test]
fn spline_and_linear_converge_at_their_orders() {
    let (a, b) = (
        sine_errors(&sine_table(11, Interpolation::CubicSpline)),
        sine_errors(&sine_table(21, Interpolation::CubicSpline)),
    );
    for (i, want) in [4.0, 3.0, 2.0].into_iter().enumerate() {
        let order = (a[i] / b[i]).log2();
        assert!((order - want).abs() < 0.3, "derivative {i}: order {order}");
    }
    assert!(b[0] < 2e-5, "{b:?}");
    let (a, b) = (
        sine_errors(&sine_table(11, Interpolation::Linear)),
        sine_errors(&sine_table(21, Interpolation::Linear)),
    );
    let order = (a[0] / b[0]).log2();
    assert!((order - 2.0).abs() < 0.3, "linear: order {order}");
}

/// The derivatives are those of the interpolant: central differences of the value and of the
/// first derivative agree with them inside intervals of an unevenly sampled table.
#[test]
fn derivatives_match_finite_differences() {
    let t = vec![0.0, 0.3, 0.45, 1.0, 1.7, 2.0];
    let y = vec![1.0, -0.5, 0.2, 2.0, 1.5, 1.6];
    let table = Table::new(t, y, Interpolation::CubicSpline).unwrap();
    let e = 1e-6;
    for &t in &[0.1, 0.4, 0.7, 1.3, 1.9] {
        let [_, d1, d2] = table.eval(t);
        let fd1 = (table.eval(t + e)[0] - table.eval(t - e)[0]) / (2.0 * e);
        let fd2 = (table.eval(t + e)[1] - table.eval(t - e)[1]) / (2.0 * e);
        assert!((d1 - fd1).abs() < 1e-7, "t = {t}: {d1} {fd1}");
        assert!((d2 - fd2).abs() < 1e-6, "t = {t}: {d2} {fd2}");
    }
}

/// The spline passes through every sample, its second derivative is continuous at the inner
/// samples and zero at the ends.
#[test]
fn spline_interpolates_and_is_c2() {
    let t = vec![0.0, 0.3, 0.45, 1.0, 1.7, 2.0];
    let y = vec![1.0, -0.5, 0.2, 2.0, 1.5, 1.6];
    let table = Table::new(t.clone(), y.clone(), Interpolation::CubicSpline).unwrap();
    for (ti, yi) in t.iter().zip(&y) {
        assert!((table.eval(*ti)[0] - yi).abs() < 1e-14, "{ti}");
    }
    for &ti in &t[1..5] {
        let (l, r) = (table.eval(ti - 1e-12), table.eval(ti + 1e-12));
        assert!(
            (l[1] - r[1]).abs() < 1e-9 && (l[2] - r[2]).abs() < 1e-9,
            "{ti}"
        );
    }
    assert!(table.eval(0.0)[2].abs() < 1e-14 && table.eval(2.0)[2].abs() < 1e-14);
}

/// Outside the samples the table holds its end values, or continues along the end slope.
#[test]
fn extrapolation_holds_or_continues_linearly() {
    let table = Table::new(
        vec![0.0, 1.0, 3.0],
        vec![0.0, 2.0, 3.0],
        Interpolation::Linear,
    )
    .unwrap();
    assert_eq!(table.eval(-1.0), [0.0, 0.0, 0.0]);
    assert_eq!(table.eval(5.0), [3.0, 0.0, 0.0]);
    assert_eq!(table.eval(2.0), [2.5, 0.5, 0.0]);
    let table = table.with_extrapolation(Extrapolation::Linear);
    assert_eq!(table.eval(-1.0), [-2.0, 2.0, 0.0]);
    assert_eq!(table.eval(5.0), [4.0, 0.5, 0.0]);
}

/// Each bad table is refused with a message naming the sample at fault.
#[test]
fn bad_tables_are_refused() {
    let lin = Interpolation::Linear;
    let e = Table::new(vec![0.0], vec![1.0], lin).unwrap_err();
    assert_eq!(e.to_string(), "a table needs at least 2 samples, got 1");
    let e = Table::new(vec![0.0, 1.0], vec![1.0], lin).unwrap_err();
    assert_eq!(
        e.to_string(),
        "a table's 't' has 2 entries but 'values' has 1"
    );
    let e = Table::new(vec![0.0, 1.0, 1.0], vec![1.0, 2.0, 3.0], lin).unwrap_err();
    assert_eq!(
        e.to_string(),
        "sample times must strictly increase: t[2] = 1 does not exceed t[1] = 1"
    );
    let e = Table::new(vec![0.0, f64::NAN], vec![1.0, 2.0], lin).unwrap_err();
    assert_eq!(e.to_string(), "sample 1 is not finite (t = NaN, value = 2)");
}

#[test]
fn csv_with_and_without_header() {
    let text = "# a motion\ntime, x, y\n0, 1, 5\n0.5; 2; 6\n\n1.0\t3\t7\n";
    assert_eq!(
        parse_csv(text, Some("y")).unwrap(),
        (vec![0.0, 0.5, 1.0], vec![5.0, 6.0, 7.0])
    );
    assert_eq!(
        parse_csv(text, None).unwrap(),
        (vec![0.0, 0.5, 1.0], vec![1.0, 2.0, 3.0])
    );
    assert_eq!(
        parse_csv("0 1\n1 2\n", None).unwrap(),
        (vec![0.0, 1.0], vec![1.0, 2.0])
    );
    let e = parse_csv(text, Some("z")).unwrap_err();
    assert_eq!(e.0, 2);
    assert!(e.1.contains("no column named 'z'"), "{}", e.1);
    let e = parse_csv("0 1\n1 oops\n", None).unwrap_err();
    assert_eq!(e, (2, "'1 oops' is not a row of numbers".to_string()));
    let e = parse_csv("0 1\n1\n", None).unwrap_err();
    assert_eq!(
        e,
        (2, "1 field(s), the value column is number 2".to_string())
    );
    let e = parse_csv("0 1\n", Some("x")).unwrap_err();
    assert_eq!(e.0, 1);
    assert!(e.1.contains("no header line naming column 'x'"), "{}", e.1);
}

/// A table read from a file relative to the base directory; missing files name the path.
#[test]
fn file_tables_resolve_against_the_base_dir() {
    let dir = std::env::temp_dir().join(format!("mbd-table-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("m.csv"), "t,x\n0,0\n1,2\n").unwrap();
    let spec = |file: &str| -> Result<TimeFunction, String> {
        let toml = format!("kind = \"table\"\nfile = \"{file}\"\ninterpolation = \"linear\"\n");
        with_base_dir(Some(&dir), || toml::from_str(&toml)).map_err(|e| e.to_string())
    };
    let f = spec("m.csv").unwrap();
    assert_eq!(f.eval(0.25), [0.5, 2.0, 0.0]);
    let e = spec("missing.csv").unwrap_err();
    assert!(
        e.contains("table file '") && e.contains("missing.csv"),
        "{e}"
    );
    // written back inline, and read back equal
    let back: TimeFunction = toml::from_str(&toml::to_string(&f).unwrap()).unwrap();
    assert_eq!(back, f);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn inline_tables_parse_and_bad_sources_are_refused() {
    let f: TimeFunction =
        toml::from_str("kind = \"table\"\nt = [0.0, 1.0, 2.0]\nvalues = [0.0, 1.0, 0.0]\n")
            .unwrap();
    let TimeFunction::Table(table) = &f else {
        panic!("{f:?}")
    };
    assert_eq!(table.interpolation(), Interpolation::CubicSpline);
    assert_eq!(table.extrapolation(), Extrapolation::Hold);
    let e = toml::from_str::<TimeFunction>(
        "kind = \"table\"\nt = [0.0, 1.0]\nvalues = [0.0, 1.0]\nfile = \"x.csv\"\n",
    )
    .unwrap_err();
    assert!(e.to_string().contains("either inline"), "{e}");
    let e = toml::from_str::<TimeFunction>("kind = \"table\"\nt = [0.0, 1.0]\nvalues = [0.0]\n")
        .unwrap_err();
    assert!(e.to_string().contains("'values' has 1"), "{e}");
}
