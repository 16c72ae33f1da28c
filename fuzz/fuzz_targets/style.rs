//! Smear style files (TOML): any text gives Ok or Err; a style that parses compiles for a
//! unit-size scene without panicking.
#![no_main]

#[path = "../targets.rs"]
mod targets;

libfuzzer_sys::fuzz_target!(|data: &[u8]| targets::style(data));
