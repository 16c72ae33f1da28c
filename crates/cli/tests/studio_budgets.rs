//! The studio under a memory limit (`ulimit -v`): requests asking for more than a budget
//! allows (10^7 motion lines, 10,000 keystrokes, a megabyte expression, smoothing 10^9 frames,
//! a clip keyed at 0 and 20,000 s) and an expression that is NaN at some vertices are refused
//! with a JSON 4xx naming the option and the limit (or the frame and vertex), the server
//! answers the next request, and its peak memory while refusing each stays bounded. The peak
//! resident memory of each refusal (`VmHWM`, reset before each request through
//! `/proc/PID/clear_refs`) is printed as a table: run with `--nocapture` to see it.

mod common;

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};

use common::{data, file_names, rekeyed_glb, s};

/// Address space the studio may map (KiB for `ulimit -v`): 3 GiB, room for the runtime's
/// threads and the robot's prepared smear, far below what any refused request would take.
const LIMIT_KIB: u64 = 3 << 20;

struct Studio {
    child: Child,
    port: u16,
    /// Kept open: the server may print more.
    _stdout: BufReader<std::process::ChildStdout>,
}

impl Studio {
    /// `toonkit studio FILE --port 0 --no-open` under `ulimit -v`.
    fn start(file: &std::path::Path, out: &std::path::Path) -> Studio {
        let exe = env!("CARGO_BIN_EXE_toonkit");
        let script = format!(
            "ulimit -v {LIMIT_KIB} && exec '{exe}' studio '{}' --port 0 --no-open --out '{}'",
            s(file),
            s(out)
        );
        let mut child = Command::new("sh")
            .args(["-c", &script])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("run the studio");
        let mut line = String::new();
        let mut stdout = BufReader::new(child.stdout.take().unwrap());
        stdout.read_line(&mut line).unwrap();
        let port = line
            .split("127.0.0.1:")
            .nth(1)
            .and_then(|r| r.split('/').next())
            .and_then(|p| p.parse().ok())
            .unwrap_or_else(|| panic!("no address in {line:?}"));
        Studio {
            child,
            port,
            _stdout: stdout,
        }
    }

    /// One HTTP/1.1 request; returns the status and the body.
    fn request(&self, method: &str, path: &str, body: &str) -> (u16, String) {
        let mut c = TcpStream::connect(("127.0.0.1", self.port)).unwrap();
        write!(
            c,
            "{method} {path} HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nContent-Type: application/json\r\n\
             Content-Length: {}\r\nConnection: close\r\n\r\n{body}",
            self.port,
            body.len()
        )
        .unwrap();
        let mut answer = Vec::new();
        c.read_to_end(&mut answer).unwrap();
        let text = String::from_utf8_lossy(&answer).into_owned();
        let status = text
            .split_whitespace()
            .nth(1)
            .and_then(|c| c.parse().ok())
            .unwrap_or(0);
        let body = text.split("\r\n\r\n").nth(1).unwrap_or("").to_string();
        (status, body)
    }

    /// Starts measuring the peak anew: `VmHWM` is set to the current resident memory (Linux
    /// `clear_refs` value 5).
    fn reset_peak(&self) {
        std::fs::write(format!("/proc/{}/clear_refs", self.child.id()), "5").unwrap();
    }

    /// Resident memory of the server now (`VmRSS`, MiB).
    fn rss_mib(&self) -> f64 {
        self.status_mib("VmRSS:")
    }

    /// Peak resident memory of the server since the last [`Studio::reset_peak`] (`VmHWM`, MiB).
    fn peak_mib(&self) -> f64 {
        self.status_mib("VmHWM:")
    }

    fn status_mib(&self, key: &str) -> f64 {
        let status = std::fs::read_to_string(format!("/proc/{}/status", self.child.id())).unwrap();
        let kib: f64 = status
            .lines()
            .find(|l| l.starts_with(key))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|v| v.parse().ok())
            .unwrap();
        kib / 1024.0
    }
}

impl Drop for Studio {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// One request the studio must refuse: what it asks for, the route, the body (GET when
/// empty), the status and a phrase of the one-line message.
struct Refusal {
    what: &'static str,
    method: &'static str,
    path: String,
    body: String,
    status: u16,
    needle: String,
}

/// Sends each refusal, asserts its status, its one-line JSON message and that the next request
/// is answered, and prints the server's peak memory while refusing it.
fn refuse_each(studio: &Studio, refusals: &[Refusal]) -> Vec<(String, f64)> {
    let mut peaks = Vec::new();
    for r in refusals {
        studio.reset_peak();
        let before = studio.rss_mib();
        let (status, answer) = studio.request(r.method, &r.path, &r.body);
        let peak = studio.peak_mib();
        assert_eq!(status, r.status, "{}: {answer}", r.what);
        let error = serde_json::from_str::<serde_json::Value>(&answer).unwrap()["error"]
            .as_str()
            .unwrap()
            .to_string();
        assert!(error.contains(&r.needle), "{}: {error}", r.what);
        assert!(
            !error.contains('\n') && error.len() < 400,
            "one line: {error}"
        );
        // The server answers the next request.
        let (next, _) = studio.request("GET", "/api/info", "");
        assert_eq!(next, 200, "after {}", r.what);
        println!(
            "| {:<44} | {:>9} | {:>4} | {:>6.0} | {:>6.0} |",
            r.what,
            r.body.len(),
            status,
            before,
            peak
        );
        peaks.push((r.what.to_string(), peak));
    }
    peaks
}

fn table_header() {
    println!(
        "| {:<44} | {:>9} | {:>4} | {:>6} | {:>6} |",
        "request", "bytes", "HTTP", "RSS", "peak"
    );
    println!("|{:-<46}|{:-<11}|{:-<6}|{:-<8}|{:-<8}|", "", "", "", "", "");
}

/// The largest peak a refusal may reach (MiB): the robot's prepared smear and the runtime sit
/// at about 100 MiB; a refusal checks its sizes before allocating, so it adds little.
const MAX_REFUSAL_PEAK_MIB: f64 = 500.0;

fn post(
    what: &'static str,
    path: &str,
    body: serde_json::Value,
    status: u16,
    needle: &str,
) -> Refusal {
    Refusal {
        what,
        method: "POST",
        path: path.to_string(),
        body: body.to_string(),
        status,
        needle: needle.to_string(),
    }
}

#[cfg(target_os = "linux")]
#[test]
fn over_budget_requests_are_refused_and_the_studio_stays_up_under_a_memory_limit() {
    let dir = tempfile::tempdir().unwrap();
    let studio = Studio::start(&data("characters/RobotExpressive.glb"), dir.path());
    let (status, _) = studio.request("GET", "/api/info", "");
    assert_eq!(status, 200);
    // Prepare the clip once (as the page does when it opens), so that the refusals below
    // measure themselves, not the first preparation.
    let (status, _) = studio.request("GET", "/api/smear/offsets?clip=Wave", "");
    assert_eq!(status, 200);
    println!(
        "studio after start and preparing Wave: {:.0} MiB",
        studio.rss_mib()
    );

    let keystrokes: Vec<serde_json::Value> = (0..10_000)
        .map(|k| serde_json::json!({"frame": k, "points": [[10.0, 10.0], [20.0, 40.0 + k as f64 % 7.0]]}))
        .collect();
    let long_expr = format!("delta{}", " + delta".repeat(150_000));
    let style = |toml: String| serde_json::json!({"clip": "Wave", "toml": toml});
    let refusals = vec![
        post(
            "10^7 motion lines (--count 1e7)",
            "/api/smear/stylize",
            style("[lines]\ncount = 10000000\n".into()),
            413,
            "is over the limit of",
        ),
        post(
            "10,000 keystrokes",
            "/api/loa/animate",
            serde_json::json!({"keystrokes": keystrokes, "width": 800, "height": 600}),
            413,
            "keystrokes = 10000 is over the limit of 1000",
        ),
        post(
            "2 keystrokes 500,000 frames apart",
            "/api/loa/animate",
            serde_json::json!({"keystrokes": [
                {"frame": 0, "points": [[10.0, 10.0], [20.0, 40.0], [30.0, 80.0]]},
                {"frame": 500_000i64, "points": [[10.0, 10.0], [20.0, 40.0], [30.0, 80.0]]},
            ], "width": 800, "height": 600}),
            413,
            "line frames (first keystroke to last, then the settle frames) = 1000001 is over the limit",
        ),
        post(
            "a 1.2 MB expression",
            "/api/smear/stylize",
            style(format!(
                "[elongate]\nfunction = {{ expr = \"{long_expr}\" }}\n"
            )),
            400,
            "expression length (bytes)",
        ),
        post(
            "smoothing over 10^9 frames (--smooth 1e9)",
            "/api/smear/stylize",
            style("[offsets]\nsmooth = 1000000000\n[elongate]\n".into()),
            413,
            "--smooth = 1e9 is over the limit of 100000",
        ),
        post(
            "an expression NaN at some vertices",
            "/api/smear/stylize",
            style("[elongate]\nfunction = { expr = \"sqrt(x)\" }\n".into()),
            400,
            "expression 'sqrt(x)' is NaN or infinite at frame ",
        ),
        post(
            "exporting it",
            "/api/smear/export",
            serde_json::json!({"clip": "Wave", "name": "nan.glb",
                "toml": "[elongate]\nfunction = { expr = \"sqrt(x)\" }\n"}),
            400,
            ", vertex ",
        ),
    ];
    table_header();
    let peaks = refuse_each(&studio, &refusals);
    assert!(file_names(dir.path()).is_empty(), "nothing exported");
    for (what, peak) in peaks {
        assert!(peak < MAX_REFUSAL_PEAK_MIB, "{what}: peak {peak:.0} MiB");
    }
}

/// `toonkit studio` on a clip keyed at 0 and 20,000 s (the robot, skins and morph targets):
/// it starts, says which clip is over the frame budget when a page asks for it, and stays up.
#[cfg(target_os = "linux")]
#[test]
fn a_clip_keyed_at_20000_seconds_is_refused_by_the_studio_which_stays_up() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("late.glb");
    rekeyed_glb(
        &data("characters/RobotExpressive.glb"),
        &[0.0, 20_000.0],
        &input,
    );
    let before = std::fs::read(&input).unwrap();
    let out = dir.path().join("out");
    let studio = Studio::start(&input, &out);
    let (status, _) = studio.request("GET", "/api/info", "");
    assert_eq!(status, 200);
    let needle = "frames at 24 fps = 480001 is over the limit of 100000";
    let get = |what, path: &str| Refusal {
        what,
        method: "GET",
        path: path.to_string(),
        body: String::new(),
        status: 413,
        needle: format!("late.glb: {needle}"),
    };
    let refusals = vec![
        get(
            "offsets of a clip of 480,001 frames",
            "/api/smear/offsets?clip=Wave",
        ),
        post(
            "its stylization",
            "/api/smear/stylize",
            serde_json::json!({"clip": "Wave", "toml": "[elongate]\n"}),
            413,
            needle,
        ),
    ];
    table_header();
    let peaks = refuse_each(&studio, &refusals);
    for (what, peak) in peaks {
        assert!(peak < MAX_REFUSAL_PEAK_MIB, "{what}: peak {peak:.0} MiB");
    }
    // Segmenting runs as a job, but its clip is sampled before the job starts: the request
    // itself is refused with the same one line, no job is made.
    let (status, answer) = studio.request(
        "POST",
        "/api/stopmo/segment",
        &serde_json::json!({"clip": "Wave", "seeds": [[0], [1]]}).to_string(),
    );
    assert_eq!(status, 413, "{answer}");
    let error = serde_json::from_str::<serde_json::Value>(&answer).unwrap()["error"]
        .as_str()
        .map(str::to_string)
        .unwrap_or_default();
    assert!(error.contains(needle) && !error.contains('\n'), "{error}");
    let (next, _) = studio.request("GET", "/api/info", "");
    assert_eq!(next, 200);
    assert_eq!(std::fs::read(&input).unwrap(), before, "input unchanged");
}
