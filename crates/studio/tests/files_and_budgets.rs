//! The studio never writes over a file it opened, sixteen exports of one name at once all
//! succeed (each write has its own temporary name), and a `.gltf` whose buffers point
//! outside its folder is not opened.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use axum::http::StatusCode;
use serde_json::json;
use studio::files::{output_folder, OpenedFile};
use studio::{router, Studio};

mod common;
use common::{error_of, post, send, PORT};

/// The robot copied into `dir`, opened by a studio whose output folder is `dir` too.
fn studio_over_its_input(dir: &Path) -> (axum::Router, PathBuf) {
    let robot = dir.join("robot.glb");
    std::fs::copy(testdata::asset("characters/RobotExpressive.glb"), &robot).unwrap();
    let opened = vec![OpenedFile::open(&robot).unwrap()];
    let studio = Arc::new(Studio::new(opened, output_folder(dir).unwrap()));
    (router(studio, PORT), robot)
}

#[tokio::test]
async fn an_export_over_the_opened_file_is_refused_and_keeps_every_byte() {
    let dir = tempfile::tempdir().unwrap();
    let (app, robot) = studio_over_its_input(dir.path());
    let before = std::fs::read(&robot).unwrap();
    let (status, body) = send(
        &app,
        post(
            "/api/smear/export",
            json!({"clip": "Wave", "name": "robot.glb", "toml": "[elongate]\n"}),
        ),
    )
    .await;
    assert_eq!(status, StatusCode::CONFLICT);
    let error = error_of(&body);
    assert!(
        error.contains("robot.glb") && error.contains("is the input") && !error.contains('\n'),
        "{error}"
    );
    assert_eq!(std::fs::read(&robot).unwrap(), before);
    assert_eq!(
        testdata::file_names(dir.path()),
        ["robot.glb"],
        "no temporary left"
    );
    // Through a symlink in the output folder: the studio writes through no link at all.
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&robot, dir.path().join("link.glb")).unwrap();
        let (status, body) = send(
            &app,
            post(
                "/api/smear/export",
                json!({"clip": "Wave", "name": "link.glb", "toml": "[elongate]\n"}),
            ),
        )
        .await;
        assert_eq!(status, StatusCode::FORBIDDEN, "{}", error_of(&body));
        assert!(error_of(&body).contains("link.glb: is a symbolic link"));
        assert_eq!(std::fs::read(&robot).unwrap(), before);
    }
}

/// Sixteen exports of one name at the same time: every one is answered 200 (the temporary
/// name is unique per write, not per process), and the file left is a whole glb.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn sixteen_concurrent_exports_of_one_name_all_succeed() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let app = common::app(&out);
    let tasks: Vec<_> = (0..16)
        .map(|_| {
            let app = app.clone();
            tokio::spawn(async move {
                send(
                    &app,
                    post(
                        "/api/smear/export",
                        json!({"clip": "Wave", "name": "same.glb", "toml": "[elongate]\n"}),
                    ),
                )
                .await
            })
        })
        .collect();
    for t in tasks {
        let (status, body) = t.await.unwrap();
        assert_eq!(status, StatusCode::OK, "{}", String::from_utf8_lossy(&body));
    }
    assert_eq!(
        testdata::file_names(&out),
        ["same.glb"],
        "no temporary left"
    );
    let scene = tkio::gltf::read(&out.join("same.glb")).unwrap();
    assert!(!scene.meshes.is_empty());
}

/// Buffer URIs that leave the file's folder (absolute, `..`, `file:`, a device) are refused
/// when the studio opens the file, naming the URI and the rule.
#[test]
fn a_gltf_reading_outside_its_folder_is_not_opened() {
    let dir = tempfile::tempdir().unwrap();
    for uri in ["/etc/hostname", "../x.bin", "file:///dev/zero", "/dev/zero"] {
        let path = testdata::gltf_with_buffer_uri(dir.path(), uri);
        let Err(error) = OpenedFile::open(&path) else {
            panic!("{uri}: opened")
        };
        let error = error.to_string();
        assert!(
            error.contains("escape.gltf") && error.contains(uri) && !error.contains('\n'),
            "{uri}: {error}"
        );
    }
}
