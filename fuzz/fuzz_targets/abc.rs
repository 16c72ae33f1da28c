//! Alembic (Ogawa) archives from bytes: any bytes give Ok or Err; an archive that reads
//! gives every mesh's samples without panicking.
#![no_main]

#[path = "../targets.rs"]
mod targets;

libfuzzer_sys::fuzz_target!(|data: &[u8]| targets::abc(data));
