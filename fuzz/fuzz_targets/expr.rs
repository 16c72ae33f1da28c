//! Stylization expressions: any text gives Ok or Err; an expression that compiles evaluates
//! (to any number, NaN included) on ordinary and extreme inputs without panicking.
#![no_main]

#[path = "../targets.rs"]
mod targets;

libfuzzer_sys::fuzz_target!(|data: &[u8]| targets::expr(data));
