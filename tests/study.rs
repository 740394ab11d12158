//! The density study's tools: the `study` module's helpers, the provenance lines its committed
//! files carry, and the instantaneous comparison's tables against its own per-swimmer rows.

use crate::common::cli::{case, case_dir, check, swimlab};

/// Rows of a CSV file whose notes are `# ` lines, as maps from column to text.
fn csv_rows(path: &std::path::Path) -> Vec<std::collections::HashMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_reader(text.as_bytes());
    let head: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            head.iter()
                .cloned()
                .zip(r.iter().map(String::from))
                .collect()
        })
        .collect()
}

#[test]
fn the_study_module_measures_what_it_says() {
    let out = case(
        "import \"study\" as study;\n\
         print(study::quantile([3.0, 1.0, 2.0, 4.0], 0.5));\n\
         print(study::quantile([3.0, 1.0, 2.0, 4.0], 0.9));\n\
         print(study::nearest([[0.0, 0.0, 0.0], [0.9, 0.0, 0.0], [0.45, 0.0, 0.0]], 1.0));\n\
         print(study::minimum_image([0.7, -0.6, 0.2], 1.0));\n\
         let d = dumbbell(#{ a1: 1.125e-6, a2: 0.5625e-6 });\n\
         let st = study::suspension(d, 0.03, 2, 5, \"two\");\n\
         let reach = d.ell + d.lambda + d.a1 + d.a2;\n\
         print(`count ${st.n} even ${st.n % 2 == 0} scene ${st.scene.count} fits ${st.side > 2.0 * reach}`);\n\
         let phases = st.scene.phases;\n\
         print(`two populations ${phases.filter(|p| p == 0.0).len() == st.n / 2}`);",
        &[],
        0,
    );
    let lines: Vec<&str> = out.lines().collect();
    // Linear interpolation between order statistics: the median of 1, 2, 3, 4 is 2.5, the 90th
    // percentile lies 0.7 of the way from 3 to 4.
    assert_eq!(lines[0], "2.5");
    let p90: f64 = lines[1].parse().unwrap();
    assert!((p90 - 3.7).abs() < 1e-12, "{p90}");
    // 0 and 0.9 are 0.1 apart through the face of the unit box.
    let near: Vec<f64> = lines[2]
        .trim_matches(['[', ']'])
        .split(',')
        .map(|x| x.trim().parse().unwrap())
        .collect();
    for (got, want) in near.iter().zip([0.1, 0.1, 0.45]) {
        assert!((got - want).abs() < 1e-12, "{near:?}");
    }
    let image: Vec<f64> = lines[3]
        .trim_matches(['[', ']'])
        .split(',')
        .map(|x| x.trim().parse().unwrap())
        .collect();
    for (got, want) in image.iter().zip([-0.3, 0.4, 0.2]) {
        assert!((got - want).abs() < 1e-12, "{image:?}");
    }
    // Two swimmers at 3% would make a box shorter than a swimmer's reach: the count is raised.
    let count: usize = lines[4].split_whitespace().nth(1).unwrap().parse().unwrap();
    assert!(count > 2, "{}", lines[4]);
    assert!(
        lines[4].ends_with(&format!("even true scene {count} fits true")),
        "{}",
        lines[4]
    );
    assert_eq!(lines[5], "two populations true");
}

#[test]
fn notes_come_first_as_comment_lines_and_run_info_names_the_build() {
    let dir = case_dir();
    let script = "let i = run_info();\n\
                  write_csv(\"t.csv\", [\"a\"], [#{ a: 1.5 }], #{ notes: [`command: ${i.command}`, `build: ${i.build}`, `machine: ${i.machine}`] });\n\
                  write_csv(\"u.csv\", [\"a\"], [#{ a: 2 }], #{ notes: \"one line\\nand another\" });\n\
                  try { write_csv(\"v.csv\", [\"a\"], [#{ a: 1 }], #{ note: [\"x\"] }); } catch (e) { print(e); }\n\
                  try { write_csv(\"v.csv\", [\"a\"], [#{ a: 1 }], #{ notes: [1] }); } catch (e) { print(e); }";
    std::fs::write(dir.join("case.rhai"), script).unwrap();
    let out = swimlab(&["run", "case.rhai"], "", &dir);
    let text = check(script, &out, &[], 0);
    assert!(
        text.contains("unknown option \"note\"") && text.contains("#{ notes: "),
        "{text}"
    );
    assert!(
        text.contains("each note is a text") && text.contains("got 1"),
        "{text}"
    );
    assert!(!dir.join("v.csv").exists(), "a refused call wrote a file");
    let t = std::fs::read_to_string(dir.join("t.csv")).unwrap();
    let lines: Vec<&str> = t.lines().collect();
    assert_eq!(lines[0], "# command: swimlab run case.rhai", "{t}");
    assert!(
        lines[1].starts_with(&format!(
            "# build: swimlab {} (commit ",
            env!("CARGO_PKG_VERSION")
        )),
        "{t}"
    );
    assert!(
        lines[2].starts_with("# machine: ") && lines[2].contains("logical cores"),
        "{t}"
    );
    assert_eq!(&lines[3..], ["a", "1.5"], "{t}");
    let rows = csv_rows(&dir.join("t.csv"));
    assert_eq!(rows[0]["a"], "1.5");
    let u = std::fs::read_to_string(dir.join("u.csv")).unwrap();
    assert!(u.starts_with("# one line\n# and another\na\n2\n"), "{u}");
}

/// The instantaneous comparison's per-density table holds the statistics of its own swimmer
/// rows, and the rigid-stroke model's own error (at tol against tol/100) is far below the
/// models' difference it measures.
#[test]
fn the_instantaneous_study_tables_follow_from_its_swimmer_rows() {
    let dir = case_dir();
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scripts/study/instantaneous.rhai"
    );
    let out = swimlab(
        &[
            "run",
            script,
            "--quick",
            "--set",
            "densities=0.003",
            "--set",
            "open=true",
            "--set",
            "out=inst",
        ],
        "",
        &dir,
    );
    check("instantaneous --quick", &out, &["wrote inst.csv"], 0);
    let swimmers = csv_rows(&dir.join("inst_swimmers.csv"));
    let table = csv_rows(&dir.join("inst.csv"));
    let num = |s: &str| s.parse::<f64>().unwrap();
    // Two placements of the quick mode, every swimmer of each.
    let n = num(&table[0]["n"]) as usize;
    assert_eq!(swimmers.len(), 2 * n);
    let mut ev: Vec<f64> = swimmers
        .iter()
        .map(|r| num(&r["dv"]) / num(&r["v"]))
        .collect();
    ev.sort_by(f64::total_cmp);
    let m = ev.len();
    let median = 0.5 * (ev[m / 2 - 1] + ev[m / 2]);
    // The same numbers through the same arithmetic, up to the order of additions.
    assert!(
        (num(&table[0]["v_median"]) - median).abs() < 1e-12 * median,
        "{} vs {median}",
        table[0]["v_median"]
    );
    let (mut sd, mut sv) = (0.0, 0.0);
    for r in &swimmers {
        sd += num(&r["dv"]).powi(2);
        sv += num(&r["v"]).powi(2);
    }
    let rms = (sd / sv).sqrt();
    assert!((num(&table[0]["v_rms"]) - rms).abs() < 1e-12 * rms);
    // At tol 1e-4 the rigid model's step error is ~1e-4 of a swimmer's drift (its error scale),
    // so its own error lies well under 1e-2 while the models differ by tens of percent.
    let own = num(&table[0]["own_error_v_rms"]);
    assert!(own < 1e-2 && own < 0.1 * rms, "own {own}, models {rms}");
    assert!(num(&table[0]["open_v_rms"]) > 0.0 && num(&table[0]["first_v_rms"]) > 0.0);
    assert!(dir.join("inst_density.svg").exists() && dir.join("inst_nearest.svg").exists());
}
