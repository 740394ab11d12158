//! Every picture function writes a file that parses back: SVG text with the size and every
//! series' colour, PNG pixels with the size and every series' colour; scene snapshots; text plots;
//! the figure scripts' pictures (make-figures in quick mode); progress bars only at a terminal.

use std::path::{Path, PathBuf};
use std::process::Command;
use swimlab::engine::{Dumbbell, Scene};
use swimlab::plot::{render_text, snapshot, Figure, Series, SnapshotOptions, Style, COLORS};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("swimlab-pictures-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn figure(n: usize) -> Figure {
    Figure {
        title: "test".into(),
        x_label: "x [m]".into(),
        y_label: "y [1]".into(),
        log_y: true,
        series: (0..n)
            .map(|k| Series {
                label: format!("series {k}"),
                x: (1..20).map(|i| i as f64).collect(),
                y: (1..20).map(|i| (i as f64).powi(k as i32 + 1)).collect(),
                style: if k % 2 == 0 {
                    Style::Line
                } else {
                    Style::Points
                },
                color: None,
            })
            .collect(),
        ..Figure::default()
    }
}

/// (width, height, RGB pixels) of a PNG file.
fn read_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb, "plotters writes RGB");
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

fn pixels_of(rgb: &[u8], c: (u8, u8, u8)) -> usize {
    rgb.chunks(3).filter(|p| (p[0], p[1], p[2]) == c).count()
}

#[test]
fn svg_has_the_size_and_every_series() {
    let f = figure(3);
    let path = dir("svg").join("p.svg");
    f.save(&path).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains("width=\"800\"") && svg.contains("height=\"500\""));
    for (r, g, b) in &COLORS[..3] {
        let hex = format!("#{r:02X}{g:02X}{b:02X}");
        assert!(svg.contains(&hex), "series colour {hex} missing");
    }
    // The fourth colour was not used.
    let (r, g, b) = COLORS[3];
    assert!(!svg.contains(&format!("#{r:02X}{g:02X}{b:02X}")));
    assert!(svg.contains("series 2") && svg.contains("x [m]"));
}

#[test]
fn png_has_the_size_and_every_series() {
    let mut f = figure(4);
    f.width = 640;
    f.height = 400;
    let path = dir("png").join("p.png");
    f.save(&path).unwrap();
    let (w, h, rgb) = read_png(&path);
    assert_eq!((w, h), (640, 400));
    for (k, c) in COLORS[..4].iter().enumerate() {
        assert!(pixels_of(&rgb, *c) > 20, "series {k} not drawn");
    }
    assert_eq!(pixels_of(&rgb, COLORS[4]), 0);
    // Text is drawn with the embedded font: dark pixels beyond the black axes lines exist.
    assert!(pixels_of(&rgb, (0, 0, 0)) > 500);
}

/// A legend "outside" sits right of the plot: every series' swatch is drawn in the strip beyond
/// the plot's right edge, where no data can be (the data span the plot only).
#[test]
fn an_outside_legend_is_drawn_beside_the_data() {
    let mut f = figure(3);
    f.legend = swimlab::plot::Legend::Outside;
    let path = dir("outside").join("p.png");
    f.save(&path).unwrap();
    let (w, h, rgb) = read_png(&path);
    // The legend strip: the right 120 px (the legend area of 8-character labels is 122 px).
    let strip: Vec<u8> = (0..h as usize)
        .flat_map(|y| {
            let row = &rgb[3 * (y * w as usize)..3 * ((y + 1) * w as usize)];
            row[3 * (w as usize - 120)..].to_vec()
        })
        .collect();
    for (k, c) in COLORS[..3].iter().enumerate() {
        assert!(
            pixels_of(&strip, *c) > 5,
            "series {k}'s swatch is not beside the plot"
        );
    }
    assert!(swimlab::plot::Legend::parse("outside").is_ok());
    let e = swimlab::plot::Legend::parse("outsde").unwrap_err();
    assert!(e.contains("\"outside\""), "{e}");
}

/// `s.animate` writes an animated GIF: frames + 1 frames of the snapshot's size, each different
/// from the one before (eighths of a stroke: the length L(t) differs from one to the next), and
/// the scene ran the periods asked.
#[test]
fn animate_writes_a_gif_of_the_run() {
    let d = dir("animate");
    let path = d.join("pair.gif");
    let script = format!(
        "let s = scene(); s.add(dumbbell(#{{ a1: 1.125e-6, a2: 0.5625e-6 }})); let n = s.animate(\"{}\", #{{ periods: 1, frames: 8, width: 300, height: 240 }}); print(n); print(s.time / s.period);",
        path.display()
    );
    let out = swimlab(&["-e", &script], &d);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "9", "9 frames: {text}");
    let periods: f64 = lines[1].parse().unwrap();
    assert!((periods - 1.0).abs() < 1e-12, "one period run: {periods}");
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let mut dec = opts.read_info(std::fs::File::open(&path).unwrap()).unwrap();
    assert_eq!((dec.width(), dec.height()), (300, 240));
    let mut frames: Vec<Vec<u8>> = Vec::new();
    while let Some(f) = dec.read_next_frame().unwrap() {
        frames.push(f.buffer.to_vec());
    }
    assert_eq!(frames.len(), 9);
    assert!(
        frames.windows(2).all(|w| w[0] != w[1]),
        "every frame shows the stroke moving on"
    );
    let bad = swimlab(
        &[
            "-e",
            "let s = scene(); s.add(dumbbell()); s.animate(\"a.png\");",
        ],
        &d,
    );
    assert!(String::from_utf8_lossy(&bad.stderr).contains("give a path ending in .gif"));
}

#[test]
fn bad_figures_are_refused_with_the_fix() {
    let mut f = figure(1);
    f.series[0].y[3] = -1.0;
    let e = f.save(&dir("bad").join("p.png")).unwrap_err();
    assert!(
        e.contains("cannot go on a log axis") && e.contains("y[3]"),
        "{e}"
    );
    let e = figure(1).save(&dir("bad").join("p.gif")).unwrap_err();
    assert!(e.contains(".svg or .png"), "{e}");
    let mut f = figure(1);
    f.series[0].x.pop();
    assert!(f
        .save(&dir("bad").join("p.svg"))
        .unwrap_err()
        .contains("same length"));
}

#[test]
fn text_plots_mark_every_series() {
    let t = render_text(&figure(2), 40, 10).unwrap();
    assert!(t.contains('*') && t.contains('o'), "{t}");
    assert!(t.contains("series 1") && t.contains("(log)"));
    assert_eq!(t.lines().filter(|l| l.contains('|')).count(), 10);
}

#[test]
fn snapshots_draw_every_swimmer() {
    let mut s = Scene::new();
    let d = Dumbbell::default();
    for k in 0..3 {
        let dir = nalgebra::Vector3::new((k as f64).cos(), (k as f64).sin(), 0.0);
        s.add(d, nalgebra::Vector3::new(k as f64 * 12e-6, 0.0, 0.0), dir)
            .unwrap();
    }
    let path = dir("snap").join("s.png");
    snapshot(&s, &SnapshotOptions::default(), &path).unwrap();
    let (w, h, rgb) = read_png(&path);
    assert_eq!((w, h), (700, 600));
    // The rods' grey.
    assert!(pixels_of(&rgb, (90, 90, 90)) > 30);
    let svg = dir("snap").join("s.svg");
    snapshot(&s, &SnapshotOptions::default(), &svg).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert_eq!(
        text.matches("<circle").count(),
        2 * 2 * 3,
        "two discs per sphere (fill, outline)"
    );
    let e = snapshot(&Scene::new(), &SnapshotOptions::default(), &path).unwrap_err();
    assert!(e.contains("no swimmers"), "{e}");
}

fn swimlab(args: &[&str], cwd: &Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_swimlab"))
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap()
}

// The figure scripts in quick mode, as CI runs them: every picture exists and parses.
#[test]
fn make_figures_renders_every_paper_figure() {
    let d = dir("figures");
    let out = swimlab(&["make-figures", "--quick", "--out", "copies"], &d);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let names = [
        "fig1a_mean",
        "fig1a_separation",
        "fig1b_mean",
        "fig1b_separation",
        "fig2a_drift",
        "fig2a_separation",
        "fig2b_drift",
        "fig2b_separation",
        "fig3_dq",
        "fig3_dD",
        "fig4_dq",
        "fig4_dD",
    ];
    for n in names {
        for p in [
            d.join("out/paper").join(format!("{n}.png")),
            d.join("copies").join(format!("{n}.png")),
        ] {
            let (w, h, rgb) = read_png(&p);
            assert_eq!((w, h), (800, 500), "{}", p.display());
            assert!(
                pixels_of(&rgb, COLORS[0]) > 0,
                "{}: first case not drawn",
                p.display()
            );
        }
    }
}

// Progress bars go to terminals only: in a pipe, a run of a few seconds prints nothing extra.
#[test]
fn no_progress_bar_in_pipes() {
    let out = swimlab(
        &[
            "-e",
            "let s = scene(); s.add(dumbbell()); s.run_periods(1500); s.count",
        ],
        &dir("pipe"),
    );
    assert!(out.status.success());
    assert_eq!(String::from_utf8_lossy(&out.stdout).trim(), "1");
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
