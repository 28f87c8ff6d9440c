//! Foxglove live: the MCAP recorder's channels served over the Foxglove WebSocket protocol (the
//! foxglove crate's server), so that Foxglove Studio's "Open connection" shows the run as it goes.
//!
//! The messages are the MCAP's own: the recorder encodes each once, and the writer thread hands the
//! same bytes to the file and to this server's `Context` (one raw channel per MCAP channel, same
//! topic, schema, encoding and metadata). Messages that are published once (the URDF, the commanded
//! path) are latched: a client that subscribes later gets the last one.

use foxglove::websocket::{ChannelView, Client, ServerListener};
use foxglove::{ChannelBuilder, Context, PartialMetadata, RawChannel, Schema, WebSocketServer, WebSocketServerHandle};
use std::collections::{BTreeMap, HashMap};
use std::sync::{Arc, Mutex};

/// Where `--foxglove` serves by default (Foxglove Studio's default connection).
pub const DEFAULT_ADDRESS: &str = "127.0.0.1:8765";

/// The last message of each latched channel, by the live channel's id.
#[derive(Default)]
struct Latched {
    channels: HashMap<u64, (Arc<RawChannel>, Vec<u8>, u64)>,
}

/// Re-sends a latched channel's last message to whoever just subscribed to it.
struct Resend(Arc<Mutex<Latched>>);

impl ServerListener for Resend {
    fn on_subscribe(&self, _client: Client, channel: ChannelView) {
        let latched = self.0.lock().expect("latch lock");
        if let Some((raw, bytes, log_time)) = latched.channels.get(&u64::from(channel.id())) {
            raw.log_with_meta(bytes, PartialMetadata { log_time: Some(*log_time) });
        }
    }
}

/// The running server with its channels, indexed by the MCAP channel id they mirror.
pub struct FoxgloveLive {
    context: Arc<Context>,
    handle: Option<WebSocketServerHandle>,
    address: String,
    channels: Vec<Option<(Arc<RawChannel>, bool)>>,
    latched: Arc<Mutex<Latched>>,
}

impl FoxgloveLive {
    /// Starts serving at `address` (`HOST:PORT`; port 0 picks a free one).
    pub fn start(address: &str) -> Result<Self, String> {
        let (host, port) = address.rsplit_once(':').ok_or_else(|| format!("'{address}' is not HOST:PORT"))?;
        let port: u16 = port.parse().map_err(|_| format!("'{port}' is not a port number"))?;
        let context = Context::new();
        let latched = Arc::new(Mutex::new(Latched::default()));
        let handle = WebSocketServer::new()
            .name("armscope")
            .bind(host.trim_matches(|c| c == '[' || c == ']'), port)
            .context(&context)
            .listener(Arc::new(Resend(latched.clone())))
            .start_blocking()
            .map_err(|e| format!("cannot serve Foxglove at {address}: {e}"))?;
        let address = format!("{host}:{}", handle.port());
        Ok(Self { context, handle: Some(handle), address, channels: Vec::new(), latched })
    }

    /// `HOST:PORT` the server listens on (the real port when 0 was asked for).
    pub fn address(&self) -> &str {
        &self.address
    }

    /// Mirrors MCAP channel `mcap_id`; a `latched` channel's last message goes to late subscribers.
    pub fn add_channel(&mut self, mcap_id: u16, topic: &str, message_encoding: &str, schema: Option<Schema>, metadata: BTreeMap<String, String>, latched: bool) -> Result<(), String> {
        let raw = ChannelBuilder::new(topic)
            .message_encoding(message_encoding)
            .schema(schema)
            .metadata(metadata)
            .context(&self.context)
            .build_raw()
            .map_err(|e| format!("Foxglove channel {topic}: {e}"))?;
        let i = usize::from(mcap_id);
        if self.channels.len() <= i {
            self.channels.resize(i + 1, None);
        }
        self.channels[i] = Some((raw, latched));
        Ok(())
    }

    /// Sends one encoded message of MCAP channel `mcap_id` to the subscribed clients.
    pub fn log(&self, mcap_id: u16, bytes: &[u8], log_time: u64) {
        let Some(Some((raw, latched))) = self.channels.get(usize::from(mcap_id)) else { return };
        if *latched {
            let mut l = self.latched.lock().expect("latch lock");
            l.channels.insert(u64::from(raw.id()), (raw.clone(), bytes.to_vec(), log_time));
        }
        raw.log_with_meta(bytes, PartialMetadata { log_time: Some(log_time) });
    }

    /// Stops the server, letting the clients' queued messages go out first.
    pub fn stop(&mut self) {
        if let Some(handle) = self.handle.take() {
            handle.stop().wait_blocking();
        }
    }
}

impl Drop for FoxgloveLive {
    fn drop(&mut self) {
        self.stop();
    }
}
