//! The MCAP output both encodings of the recording share: the file (or the live Foxglove
//! clients, or both) written on a thread of its own from batches of encoded messages, channels and
//! metadata added before the thread starts.

use super::McapOptions;
use super::live::FoxgloveLive;
use crate::error::Error;
use crate::recorder::shared::output_file::Replaced;
use crate::recorder::shared::worker::{BatchWorker, Reusable};
use foxglove::Encode;
use mcap::records::MessageHeader;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::marker::PhantomData;

/// A channel of messages of type T.
pub(super) struct Topic<T> {
    pub(super) id: u16,
    sequence: u32,
    _message: PhantomData<T>,
}

pub(super) type McapWriter = mcap::Writer<BufWriter<File>>;

/// Encoded messages on their way to the writer thread: payloads back to back, and per message its
/// header and where its payload ends.
#[derive(Default)]
struct Batch {
    bytes: Vec<u8>,
    messages: Vec<(MessageHeader, usize)>,
}

impl Batch {
    /// An empty batch with room for a full one of the box model's messages (~400 kB): grown from
    /// nothing, it was copied along the way.
    fn sized() -> Self {
        Self { bytes: Vec::with_capacity(BATCH_MESSAGES * 512), messages: Vec::with_capacity(BATCH_MESSAGES + 1) }
    }
}

impl Reusable for Batch {
    fn clear(&mut self) {
        self.bytes.clear();
        self.messages.clear();
    }
}

/// Messages per batch: ~250 control steps.
const BATCH_MESSAGES: usize = 1000;

/// Where the encoded messages go: the file, the live Foxglove clients, or both (the same bytes).
pub(super) struct Sinks {
    pub(super) file: Option<McapWriter>,
    pub(super) live: Option<FoxgloveLive>,
}

impl Sinks {
    fn write(&mut self, batch: &Batch) -> Result<(), String> {
        let mut start = 0;
        for (header, end) in &batch.messages {
            let bytes = &batch.bytes[start..*end];
            if let Some(file) = &mut self.file {
                file.write_to_known_channel(header, bytes).map_err(|e| e.to_string())?;
            }
            if let Some(live) = &self.live {
                live.log(header.channel_id, bytes, header.log_time);
            }
            start = *end;
        }
        Ok(())
    }
}

/// The MCAP output, written on a thread of its own: this (recorder) thread encodes the messages,
/// the writer thread frames and writes them (and with `--compress` zstds them, then the larger half
/// of the work), so the two halves run on both cores instead of one.
pub(super) struct Out {
    /// The sinks while schemas, channels and metadata are added (before `spawn`, after `close`).
    sinks: Option<Sinks>,
    batch: Batch,
    worker: Option<BatchWorker<Sinks, Batch, String>>,
    /// The next channel id when there is no file to hand them out.
    next_channel: u16,
}

impl Out {
    pub(super) fn new(sinks: Sinks) -> Self {
        Self { sinks: Some(sinks), batch: Batch::default(), worker: None, next_channel: 1 }
    }

    pub(super) fn sinks(&mut self) -> &mut Sinks {
        self.sinks.as_mut().expect("the sinks are here before spawn and after close")
    }

    /// A channel in both sinks; `latched`: a late live client gets its last message.
    pub(super) fn channel<T: Encode>(&mut self, topic: &str, metadata: BTreeMap<String, String>, latched: bool) -> Result<Topic<T>, String> {
        self.channel_of(topic, &T::get_message_encoding(), T::get_schema(), metadata, latched)
    }

    /// A channel of messages encoded `encoding` with `schema` (none: schemaless).
    pub(super) fn channel_of<T>(&mut self, topic: &str, encoding: &str, schema: Option<foxglove::Schema>, metadata: BTreeMap<String, String>, latched: bool) -> Result<Topic<T>, String> {
        let next = self.next_channel;
        let sinks = self.sinks();
        let id = match &mut sinks.file {
            Some(file) => {
                let schema_id = match &schema {
                    Some(s) => file.add_schema(&s.name, &s.encoding, &s.data).map_err(|e| e.to_string())?,
                    None => 0,
                };
                file.add_channel(schema_id, topic, encoding, &metadata).map_err(|e| e.to_string())?
            }
            None => next,
        };
        if let Some(live) = &mut sinks.live {
            live.add_channel(id, topic, encoding, schema, metadata, latched)?;
        }
        self.next_channel = id + 1;
        Ok(Topic { id, sequence: 0, _message: PhantomData })
    }

    pub(super) fn write_metadata(&mut self, name: &str, metadata: BTreeMap<String, String>) -> mcap::McapResult<()> {
        match &mut self.sinks().file {
            Some(file) => file.write_metadata(&mcap::records::Metadata { name: name.into(), metadata }),
            None => Ok(()),
        }
    }

    pub(super) fn log<T: Encode>(&mut self, topic: &mut Topic<T>, msg: &T, time_ns: u64) -> Result<(), String> {
        msg.encode(&mut self.batch.bytes).map_err(|e| e.to_string())?;
        self.logged(topic, time_ns)
    }

    /// A message of `topic` that `encode` appends to the batch's bytes (see `step_messages`).
    pub(super) fn log_encoded<T>(&mut self, topic: &mut Topic<T>, encode: impl FnOnce(&mut Vec<u8>), time_ns: u64) -> Result<(), String> {
        encode(&mut self.batch.bytes);
        self.logged(topic, time_ns)
    }

    /// The message whose bytes end the batch's.
    fn logged<T>(&mut self, topic: &mut Topic<T>, time_ns: u64) -> Result<(), String> {
        let header = MessageHeader { channel_id: topic.id, sequence: topic.sequence, log_time: time_ns, publish_time: time_ns };
        topic.sequence += 1;
        self.batch.messages.push((header, self.batch.bytes.len()));
        if self.batch.messages.len() >= BATCH_MESSAGES { self.send() } else { Ok(()) }
    }

    /// Moves the sinks to their thread; messages logged from now on are written there.
    pub(super) fn spawn(&mut self) -> Result<(), String> {
        let sinks = self.sinks.take().expect("spawned once");
        let worker = BatchWorker::spawn("McapWriter", sinks, |sinks: &mut Sinks, batch: &Batch| sinks.write(batch));
        self.worker = Some(worker.map_err(|e| e.to_string())?);
        Ok(())
    }

    fn send(&mut self) -> Result<(), String> {
        let Some(worker) = &self.worker else { return Ok(()) };
        if !worker.hand_over(&mut self.batch, Batch::sized) {
            // the writer stopped on an error: report it
            return self.join();
        }
        Ok(())
    }

    /// Writes what is left and takes the sinks back.
    fn join(&mut self) -> Result<(), String> {
        match self.worker.as_mut().and_then(BatchWorker::join) {
            Some(joined) => {
                let (sinks, result) = joined.map_err(|_| "the MCAP writer thread panicked".to_string())?;
                self.sinks = Some(sinks);
                result
            }
            None => Ok(()),
        }
    }

    pub(super) fn close(&mut self) -> Result<(), String> {
        self.send()?;
        self.join()
    }

    /// Ends the recording: every batch written, the run's summary and status as the
    /// `armscope.summary` metadata, the file's summary section and footer, the live server stopped.
    pub(super) fn finish(mut self, summary: &crate::summary::Summary) -> Result<(), String> {
        let mut meta = BTreeMap::new();
        meta.insert("summary".into(), serde_json::to_string(summary).unwrap_or_default());
        meta.insert("status".into(), serde_json::to_string(&summary.status).unwrap_or_default());
        self.close()?;
        self.write_metadata("armscope.summary", meta).map_err(|e| e.to_string())?;
        let sinks = self.sinks();
        if let Some(file) = &mut sinks.file {
            file.finish().map_err(|e| e.to_string())?;
        }
        if let Some(live) = &mut sinks.live {
            live.stop();
        }
        Ok(())
    }
}

/// zstd's fast level −3, with `--compress`: compressing was ~2/3 of this recorder's work at level
/// 1; −3 costs ~40 % less for a file ~8 % larger. Without `--compress` the chunks are stored as
/// they are: the mcap crate hands zstd each record field by field (seven streaming calls a message),
/// and compressing was a quarter of the whole run's instructions (the 30 s run's file 13.2 → 20.7 MB,
/// as readable: every MCAP reader takes uncompressed chunks; `mcap compress` makes a smaller copy).
pub(super) const ZSTD_LEVEL: i32 = -3;

/// The mcap crate takes the level as `u32` and hands it to zstd as `level as i32` (mcap 0.26,
/// `ChunkWriter::zstd_encoder`), so zstd's negative (fast) levels pass through as their two's
/// complement. The test `negative_zstd_levels_reach_zstd_through_mcap` pins that down.
pub(super) fn zstd_level(level: i32) -> u32 {
    level as u32
}


/// The run's configuration as both encodings write it (`armscope.config` metadata): model, URDF,
/// settings, gains, notices, plant, command, and how the file's timestamps relate to the run's time.
pub(super) fn config_metadata(run: &crate::recorder::RunInfo, start_ns: u64, timestamps: &str) -> std::collections::BTreeMap<String, String> {
    let (e, model) = (run.experiment, &*run.experiment.model);
    let mut meta = std::collections::BTreeMap::new();
    meta.insert("model".into(), model.name.clone());
    meta.insert("urdf".into(), model.source.display().to_string());
    meta.insert("config".into(), serde_json::to_string(&e.config).unwrap_or_default());
    meta.insert("gains".into(), serde_json::to_string(&e.gains).unwrap_or_default());
    meta.insert("notices".into(), serde_json::to_string(&model.notices).unwrap_or_default());
    meta.insert("plant".into(), run.plant.clone());
    meta.insert("command".into(), run.trajectory.clone());
    meta.insert("start_time_unix_ns".into(), start_ns.to_string());
    meta.insert("timestamps".into(), timestamps.into());
    meta
}

/// The `/controller` channel's metadata in both encodings: the joint order and torque limits,
/// constant over a run (not repeated in every message).
pub(super) fn controller_metadata(run: &crate::recorder::RunInfo) -> std::collections::BTreeMap<String, String> {
    let e = run.experiment;
    let mut meta = std::collections::BTreeMap::new();
    meta.insert("joints".to_string(), serde_json::to_string(&e.model.joints.iter().map(|j| &j.name).collect::<Vec<_>>()).unwrap_or_default());
    meta.insert("torque_limit".to_string(), serde_json::to_string(&e.controller().effort).unwrap_or_default());
    meta
}

/// The sinks of a recording: its file (the last one at its path freed meanwhile, see
/// `create_replacing`), written with `profile` in the MCAP header ("": none; "ros2"), and the live
/// Foxglove server, with `notice` told where it listens. Errors name `path_for_errors`.
pub(super) fn open_sinks(options: &McapOptions, profile: &str, path_for_errors: &std::path::Path, notice: Option<fn(&str)>) -> Result<(Sinks, Option<Replaced>), Error> {
    let mut replaced = None;
    let file = match &options.file {
        Some(path) => {
            let (file, old) = crate::recorder::shared::output_file::create_replacing(path).map_err(|err| Error::output(path_for_errors, err))?;
            replaced = Some(old);
            Some(file)
        }
        None => None,
    };
    // zstd (with --compress) on the writer thread (`Out`): zstd's own worker threads cost more
    // than they save here
    let write_options = mcap::WriteOptions::new()
        .compression(options.compress.then_some(mcap::Compression::Zstd))
        .compression_level(zstd_level(ZSTD_LEVEL))
        .compression_threads(0)
        // within zstd's window at this level, so no block takes its slower "external
        // dictionary" path (−5 % of the writer's work at the same size)
        .chunk_size(Some(512 * 1024))
        // CRCs with --compress only: the crate checksums every record field by field as it
        // writes it, twice (5 % of the run's instructions), and the data section's CRC needs
        // the chunks' (the default is rosbag2's "fastwrite": chunks as they are, no CRCs;
        // readers skip a zero CRC)
        .calculate_chunk_crcs(options.compress)
        .calculate_data_section_crc(options.compress)
        .profile(profile)
        .library(if profile == "ros2" { format!("armscope {} (ROS 2 CDR, mcap-rust)", env!("CARGO_PKG_VERSION")) } else { format!("armscope {} (foxglove-sdk schemas, mcap-rust)", env!("CARGO_PKG_VERSION")) });
    // zstd hands its output over in pieces of up to 128 KiB: gathered here, a chunk (~200 KiB
    // compressed) takes a write call or two
    let file = file.map(|file| write_options.create(BufWriter::with_capacity(1 << 20, file))).transpose().map_err(|err| Error::output(path_for_errors, err))?;
    let live = match &options.live {
        Some(address) => {
            let live = FoxgloveLive::start(address).map_err(|err| Error::flag("--foxglove", err))?;
            if let Some(notice) = notice {
                notice(&format!("Foxglove live at ws://{} (Foxglove: Open connection → Foxglove WebSocket)", live.address()));
            }
            Some(live)
        }
        None => None,
    };
    Ok((Sinks { file, live }, replaced))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same telemetry-like messages, written with zstd at `level`: the file's size.
    fn mcap_size(level: u32) -> usize {
        let options = mcap::WriteOptions::new().compression(Some(mcap::Compression::Zstd)).compression_level(level).compression_threads(0);
        let mut writer = options.create(std::io::Cursor::new(Vec::new())).unwrap();
        let channel = writer.add_channel(0, "/data", "binary", &BTreeMap::new()).unwrap();
        for k in 0..20_000u32 {
            // text with numbers, like a log line: repetitive enough that how hard zstd looks shows
            let data = format!("step {k} joint J{} angle {:.4} target {:.4}", k % 6 + 1, (k as f64 * 1e-3).sin(), (k as f64 * 1e-3).cos()).into_bytes();
            let header = MessageHeader { channel_id: channel, sequence: k, log_time: k as u64, publish_time: k as u64 };
            writer.write_to_known_channel(&header, &data).unwrap();
        }
        writer.finish().unwrap();
        writer.into_inner().into_inner().len()
    }

    #[test]
    fn negative_zstd_levels_reach_zstd_through_mcap() {
        // on this data level −3 writes 1.25× the bytes of level 1; the default level (3), level 1
        // itself, or zstd's highest (22) write 0.8–1.02×: whichever mcap made of −3 shows
        let (fast, level_1) = (mcap_size(zstd_level(ZSTD_LEVEL)), mcap_size(1));
        assert!(fast as f64 > 1.15 * level_1 as f64, "level {ZSTD_LEVEL}: {fast} bytes, level 1: {level_1}");
    }
}
