//! The `.rrd` file: Rerun's own encoder (same format, same footer), writing its chunks without
//! LZ4 unless asked (`--compress`). Rerun's `FileSink` always compresses; on armscope's recordings
//! (mostly row ids, times and floats) LZ4 saves only a third of the size but was ~40 % of all the
//! CPU the Rerun recording costs, on a machine whose two cores the simulation and both recorders
//! share. `rerun rrd optimize IN.rrd -o OUT.rrd` writes a compressed copy afterwards.

use rerun::external::re_build_info::CrateVersion;
use rerun::external::re_log_encoding::{Encoder, EncodingOptions};
use rerun::log::LogMsg;
use rerun::sink::{LogSink, SinkFlushError};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Duration;

type RrdEncoder = Encoder<BufWriter<File>>;

/// The encoder, shared between the sink (owned by the recording stream) and the recorder, which
/// closes the file itself once the stream is flushed: the file is complete when `close` returns.
#[derive(Clone)]
pub struct RrdFile {
    path: PathBuf,
    state: Arc<Mutex<State>>,
}

struct State {
    /// `None` once closed, or after a write failed.
    encoder: Option<RrdEncoder>,
    /// The last run's file at this path, freed meanwhile on another thread.
    _replaced: crate::recorder::shared::output_file::Replaced,
    error: Option<String>,
}

/// Simulated seconds up to which an `.rrd` gets Rerun's footer, the manifest of every chunk (an index
/// for random access): the encoder keeps it in memory until the end, ~6 KB per simulated second here
/// (≈ 20 MB an hour), so longer runs go without and memory stays flat; `rerun rrd optimize` adds one.
pub const FOOTER_UP_TO_SECONDS: f64 = 600.0;

impl RrdFile {
    /// `footer`: end the file with Rerun's manifest of its chunks; `compress`: LZ4 its chunks.
    pub fn create(path: &Path, footer: bool, compress: bool) -> Result<Self, String> {
        let (file, replaced) = crate::recorder::shared::output_file::create_replacing(path).map_err(|e| e.to_string())?;
        // the encoder writes each message whole: a buffer smaller than a block's chunks (100–250 KB)
        // gathers the small messages and lets the chunks go straight to the file, uncopied
        let options = if compress { EncodingOptions::PROTOBUF_COMPRESSED } else { EncodingOptions::PROTOBUF_UNCOMPRESSED };
        let mut encoder = Encoder::new_eager(CrateVersion::LOCAL, options, BufWriter::with_capacity(64 << 10, file)).map_err(|e| e.to_string())?;
        if !footer {
            encoder.do_not_emit_footer();
        }
        Ok(Self { path: path.to_path_buf(), state: Arc::new(Mutex::new(State { encoder: Some(encoder), _replaced: replaced, error: None })) })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The sink to give the recording stream.
    pub fn sink(&self) -> Box<dyn LogSink> {
        Box::new(RrdFileSink(self.clone()))
    }

    fn with_encoder(&self, f: impl FnOnce(&mut RrdEncoder) -> Result<(), String>) {
        let mut state = self.state.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if let Some(encoder) = state.encoder.as_mut()
            && let Err(e) = f(encoder)
        {
            // stop at the first failure (a full disk): the error is reported by `close`
            state.encoder = None;
            state.error.get_or_insert(e);
        }
    }

    /// Writes the footer and flushes; later messages are dropped. The first write error, if any.
    pub fn close(&self) -> Result<(), String> {
        let mut state = self.state.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if let Some(mut encoder) = state.encoder.take() {
            let closed = encoder.finish().and_then(|()| encoder.flush_blocking());
            if let Err(e) = closed {
                state.error.get_or_insert(e.to_string());
            }
        }
        state.error.clone().map_or(Ok(()), Err)
    }
}

struct RrdFileSink(RrdFile);

impl LogSink for RrdFileSink {
    fn send(&self, msg: LogMsg) {
        self.0.with_encoder(|encoder| encoder.append(&msg).map(|_| ()).map_err(|e| e.to_string()));
    }

    fn flush_blocking(&self, _timeout: Duration) -> Result<(), SinkFlushError> {
        self.0.with_encoder(|encoder| encoder.flush_blocking().map_err(|e| e.to_string()));
        let state = self.0.state.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        state.error.clone().map_or(Ok(()), |e| Err(SinkFlushError::failed(e)))
    }
}

impl Drop for State {
    /// A stream dropped without `close` (after an error elsewhere) still leaves a readable file.
    fn drop(&mut self) {
        if let Some(mut encoder) = self.encoder.take() {
            let _ = encoder.finish().and_then(|()| encoder.flush_blocking());
        }
    }
}
