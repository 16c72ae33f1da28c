//! `toonkit demo`: all three tools on the bundled inputs, one page that shows every result.

mod common;

use std::path::Path;

use common::*;

/// Every `src="…"` and `href="…"` of the page.
fn links(html: &str) -> Vec<String> {
    let mut out = Vec::new();
    for attr in ["src=\"", "href=\""] {
        let mut rest = html;
        while let Some(i) = rest.find(attr) {
            rest = &rest[i + attr.len()..];
            let end = rest.find('"').expect("closed attribute");
            out.push(rest[..end].to_string());
            rest = &rest[end..];
        }
    }
    out
}

#[test]
fn demo_writes_valid_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let v = json(&["demo", "--out", dir.path().to_str().unwrap()]);
    assert!(v["frames"].as_u64().unwrap() > 10);
    assert!(dir.path().join("robot.glb").exists());
    keep_for_validation(dir.path(), "demo");

    // One step per tool at least, each a real command line.
    let steps = v["steps"].as_array().unwrap();
    for tool in ["smear", "stopmo", "loa"] {
        assert!(
            steps.iter().any(|s| s["tool"] == tool),
            "no {tool} step in {steps:?}"
        );
    }
    assert!(steps
        .iter()
        .all(|s| s["command"].as_str().unwrap().starts_with("toonkit ")));

    // The page references only files that exist, and shows the pictures of every tool.
    let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
    let links = links(&html);
    assert!(links.len() >= 15, "{links:?}");
    for l in &links {
        let p = dir.path().join(l);
        assert!(p.is_file(), "index.html links to missing {l}");
        if l.ends_with(".png") {
            assert!(std::fs::read(&p).unwrap().starts_with(b"\x89PNG"), "{l}");
        }
        if l.ends_with(".gif") {
            assert!(std::fs::read(&p).unwrap().starts_with(b"GIF89a"), "{l}");
        }
    }
    for picture in [
        "robot_smear.gif",
        "stopmo/segmentation.png",
        "stopmo/error_curve.png",
        "jump.gif",
    ] {
        assert!(
            links.iter().any(|l| l == picture),
            "{picture} not on the page"
        );
    }
    // Each step's command reproduces its output: run one again and compare bytes.
    let again = steps
        .iter()
        .find(|s| s["command"].as_str().unwrap().contains("loa line"))
        .unwrap()["command"]
        .as_str()
        .unwrap()
        .replace("jump_line.gif", "jump_line_again.gif");
    let args: Vec<&str> = again.split(' ').skip(1).collect();
    ok(&args);
    let read = |name: &str| std::fs::read(Path::new(dir.path()).join(name)).unwrap();
    assert_eq!(read("jump_line.gif"), read("jump_line_again.gif"));
}
