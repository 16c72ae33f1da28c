//! The studio under a memory limit (`ulimit -v`): requests asking for more than a budget
//! allows (10^7 motion lines, 10,000 keystrokes, a megabyte expression) are refused with a
//! JSON 4xx naming the option and the limit, the server answers the next request, and its
//! peak memory stays bounded. The peak resident memory after each refusal is printed (run
//! with `--nocapture` to see the figures).

mod common;

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};

use common::{data, s};

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
    fn start(file: &str, out: &std::path::Path) -> Studio {
        let exe = env!("CARGO_BIN_EXE_toonkit");
        let script = format!(
            "ulimit -v {LIMIT_KIB} && exec '{exe}' studio '{}' --port 0 --no-open --out '{}'",
            s(&data(file)),
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

    /// Peak resident memory of the server so far (`VmHWM`, MiB).
    fn peak_mib(&self) -> f64 {
        let status = std::fs::read_to_string(format!("/proc/{}/status", self.child.id())).unwrap();
        let kib: f64 = status
            .lines()
            .find(|l| l.starts_with("VmHWM:"))
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

#[cfg(target_os = "linux")]
#[test]
fn over_budget_requests_are_refused_and_the_studio_stays_up_under_a_memory_limit() {
    let dir = tempfile::tempdir().unwrap();
    let mut studio = Studio::start("characters/RobotExpressive.glb", dir.path());
    let (status, _) = studio.request("GET", "/api/info", "");
    assert_eq!(status, 200);
    println!("studio peak after start: {:.0} MiB", studio.peak_mib());

    let keystrokes: Vec<serde_json::Value> = (0..10_000)
        .map(|k| serde_json::json!({"frame": k, "points": [[10.0, 10.0], [20.0, 40.0 + k as f64 % 7.0]]}))
        .collect();
    let long_expr = format!("delta{}", " + delta".repeat(150_000));
    let cases: Vec<(&str, &str, String, u16, &str)> = vec![
        (
            "10^7 motion lines",
            "/api/smear/stylize",
            serde_json::json!({"clip": "Wave", "toml": "[lines]\ncount = 10000000\n"}).to_string(),
            413,
            "is over the limit of",
        ),
        (
            "10,000 keystrokes",
            "/api/loa/animate",
            serde_json::json!({"keystrokes": keystrokes, "width": 800, "height": 600}).to_string(),
            413,
            "keystrokes = 10000 is over the limit of 1000",
        ),
        (
            "a 1.2 MB expression",
            "/api/smear/stylize",
            serde_json::json!({
                "clip": "Wave",
                "toml": format!("[elongate]\nfunction = {{ expr = \"{long_expr}\" }}\n")
            })
            .to_string(),
            400,
            "expression length (bytes)",
        ),
    ];
    for (what, path, body, want, needle) in &cases {
        let (status, answer) = studio.request("POST", path, body);
        assert_eq!(status, *want, "{what}: {answer}");
        let error = serde_json::from_str::<serde_json::Value>(&answer).unwrap()["error"]
            .as_str()
            .unwrap()
            .to_string();
        assert!(error.contains(needle), "{what}: {error}");
        assert!(
            !error.contains('\n') && error.len() < 400,
            "one line: {error}"
        );
        // The server answers the next request.
        let (next, _) = studio.request("GET", "/api/info", "");
        assert_eq!(next, 200, "after {what}");
        println!(
            "studio peak after refusing {what} ({} bytes): {:.0} MiB",
            body.len(),
            studio.peak_mib()
        );
    }
    assert!(studio.child.try_wait().unwrap().is_none(), "still running");
    assert!(
        studio.peak_mib() < 1024.0,
        "peak {:.0} MiB",
        studio.peak_mib()
    );
}
