//! One module per paper: `run(&Context) -> Result<PaperResult>` computes the paper's numbers
//! and hands them, with the paper's spec (`papers/<slug>.toml`), to [`crate::runner`].

pub mod gskf;
pub mod kf_dynamic;
pub mod kfu_lstm;
pub mod mkpf;
