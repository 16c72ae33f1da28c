//! Keystrokes from JSON or SVG text (`loa::Keystrokes::parse`): any text gives Ok or Err.
#![no_main]

#[path = "../targets.rs"]
mod targets;

libfuzzer_sys::fuzz_target!(|data: &[u8]| targets::keystrokes(data));
