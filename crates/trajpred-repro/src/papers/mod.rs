//! One module per paper; each has `run(&Context) -> Result<PaperResult>` and an
//! `EXPLANATION` for the results index.

pub mod gskf;
pub mod kf_dynamic;
pub mod kfu_lstm;
pub mod mkpf;
