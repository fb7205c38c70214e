//! Tests of the report writer.
use super::*;

fn ok_section(x: f64) -> Section {
    Section {
        summary: serde_json::json!({"paper_x": {"table": [{"v": num(x)}]}}),
        claims: vec![Claim::check("x is small", x < 1.0, format!("x = {x}"))],
        ..Default::default()
    }
}

#[test]
fn failures_are_listed_and_summary_is_deterministic() {
    let dir = std::env::temp_dir().join(format!("mbd-xtask-test-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("figures")).unwrap();
    let ctx = Ctx {
        quick: true,
        out: dir.clone(),
        jobs: 1,
    };
    let outcomes = vec![
        Outcome {
            id: "a",
            part: Part::Own,
            title: "A",
            wall_s: 0.1,
            result: Ok(ok_section(0.5)),
        },
        Outcome {
            id: "b",
            part: Part::Own,
            title: "B",
            wall_s: 0.2,
            result: Err("boom: Newton failed at t = 1".into()),
        },
        Outcome {
            id: "c",
            part: Part::Own,
            title: "C",
            wall_s: 0.3,
            result: Ok(ok_section(2.0)),
        },
    ];
    write_report(&ctx, &outcomes, 1.0, "own").unwrap();
    let md = std::fs::read_to_string(dir.join("REPORT.md")).unwrap();
    assert!(md.contains("## Failed experiments"));
    assert!(md.contains("boom: Newton failed at t = 1"));
    assert!(md.contains("**did not hold**"));
    let s1: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s1["failures"][0]["id"], "b");
    assert_eq!(s1["paper_x"]["table"].as_array().unwrap().len(), 2);
    // same outcomes, other wall times: identical apart from the timings
    let outcomes2: Vec<Outcome> = outcomes
        .into_iter()
        .map(|o| Outcome {
            wall_s: o.wall_s * 3.0,
            ..o
        })
        .collect();
    write_report(&ctx, &outcomes2, 7.0, "own").unwrap();
    let mut s2: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let mut s1 = s1;
    s1.as_object_mut().unwrap().remove("timings");
    s2.as_object_mut().unwrap().remove("timings");
    assert_eq!(s1, s2);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn claims_reach_summary_json_and_strict_spares_only_documented_misses() {
    let held = Claim::check("a", true, "1");
    let missed = Claim::check("b", false, "2");
    let expected = Claim::check("c", false, "3").expected_miss("known, see docs");
    let timing = Claim::timing("d", false, "4 us");
    let unchecked = Claim::not_checked("e", "quick");
    assert!(!held.fails_strict(false));
    assert!(missed.fails_strict(false) && missed.fails_strict(true));
    assert!(!expected.fails_strict(false));
    assert!(timing.fails_strict(false) && !timing.fails_strict(true));
    assert!(!unchecked.fails_strict(false));

    let dir = std::env::temp_dir().join(format!("mbd-xtask-claims-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("figures")).unwrap();
    let ctx = Ctx {
        quick: false,
        out: dir.clone(),
        jobs: 1,
    };
    let sec = Section {
        claims: vec![held, missed, expected, timing, unchecked],
        ..Default::default()
    };
    let outcomes = vec![Outcome {
        id: "x",
        part: Part::PaperA,
        title: "X",
        wall_s: 0.1,
        result: Ok(sec),
    }];
    write_report(&ctx, &outcomes, 1.0, "all").unwrap();
    let s: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let c = s["claims"].as_array().unwrap();
    assert_eq!(c.len(), 5);
    assert_eq!(c[0]["held"], true);
    assert_eq!(c[1]["held"], false);
    assert_eq!(c[1]["part"], "paper_a");
    assert_eq!(c[1]["measured"], "2");
    assert_eq!(c[2]["expected_miss"], "known, see docs");
    assert_eq!(c[3]["timing"], true);
    assert!(c[4]["held"].is_null());
    let md = std::fs::read_to_string(dir.join("REPORT.md")).unwrap();
    assert!(md.contains("did not hold (expected miss: known, see docs)"));
    assert!(md.contains("Wu Zhi-gang"), "the papers are cited");
    assert!(
        !md.contains("shared/"),
        "the report must not point outside the repository"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn merge_concatenates_arrays_and_merges_objects() {
    let mut a = serde_json::json!({"orders": [1], "p": {"x": 1}});
    merge(&mut a, serde_json::json!({"orders": [2], "p": {"y": 2}}));
    assert_eq!(
        a,
        serde_json::json!({"orders": [1, 2], "p": {"x": 1, "y": 2}})
    );
}
