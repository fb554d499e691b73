//! The panel's web server: the page's static files, the dependencies it
//! loads (`vendor/…`, from `panel/node_modules`), `bridge.json` (which
//! head the page is bridged to, if any) and the WebSocket `/ws` to it.
//!
//! One `std` listener: a request is read with `httparse`; a WebSocket
//! upgrade is answered and then run by `tungstenite` on the same TCP
//! stream, whose read timeout lets one thread both read the page's bytes
//! and pass on the head's. (A server crate such as `tiny_http` hands an
//! upgraded connection over as a stream that cannot time out, which a
//! two-way bridge on one thread needs.) Only GET of a file and the
//! upgrade are served: the page is static.

use std::{
    io::{ErrorKind, Read, Write},
    net::{SocketAddr, TcpListener, TcpStream},
    path::{Path, PathBuf},
    sync::{
        Arc,
        atomic::{AtomicBool, Ordering},
        mpsc,
    },
    thread,
    time::Duration,
};

use anyhow::{Context, Result};
use tungstenite::{Message, WebSocket, handshake::derive_accept_key, protocol::Role};

use super::bridge::{Bridge, Note};
use super::{VENDOR, content_type};

/// `bridge.json` of a page served without a bridge (and of an exported
/// copy): the page offers Web Serial.
pub const NO_BRIDGE: &str = r#"{"bridge":null}"#;

/// The running server; dropping it stops it (and its bridge).
pub struct Server {
    address: SocketAddr,
    bridge: Option<Arc<Bridge>>,
    stop: Arc<AtomicBool>,
}

impl Server {
    /// Serves `root`'s `panel/` on `listen`, bridged to `bridge`; a head
    /// that goes away is told on `stopped`'s channel too (the command then
    /// ends, saying so).
    pub fn start(
        root: &Path,
        listen: SocketAddr,
        bridge: Option<Bridge>,
        stopped: mpsc::Sender<String>,
    ) -> Result<Self> {
        let listener =
            TcpListener::bind(listen).with_context(|| format!("listening on {listen}"))?;
        let address = listener.local_addr()?;
        let bridge = bridge.map(Arc::new);
        let stop = Arc::new(AtomicBool::new(false));
        if let Some(bridge) = &bridge {
            let notes = bridge.hub.join();
            thread::spawn(move || {
                while let Ok(note) = notes.recv() {
                    if let Note::Gone(why) = note {
                        let _ = stopped.send(format!("the head went away ({why})"));
                        return;
                    }
                }
            });
        }
        let site = Site {
            panel: root.join("panel"),
            bridge: bridge.clone(),
            stop: Arc::clone(&stop),
        };
        let site = Arc::new(site);
        listener.set_nonblocking(true)?;
        let accepting = Arc::clone(&stop);
        thread::spawn(move || {
            while !accepting.load(Ordering::Acquire) {
                match listener.accept() {
                    Ok((stream, _)) => {
                        let site = Arc::clone(&site);
                        thread::spawn(move || {
                            let _ = stream.set_nonblocking(false);
                            let _ = site.serve(stream);
                        });
                    }
                    Err(e) if e.kind() == ErrorKind::WouldBlock => {
                        thread::sleep(Duration::from_millis(20));
                    }
                    Err(_) => thread::sleep(Duration::from_millis(20)),
                }
            }
        });
        Ok(Self {
            address,
            bridge,
            stop,
        })
    }

    /// Where it listens.
    pub fn address(&self) -> SocketAddr {
        self.address
    }

    /// What the page is bridged to, if anything.
    pub fn bridge_name(&self) -> Option<&str> {
        self.bridge.as_deref().map(|b| b.name.as_str())
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        // The connections' threads hold the bridge too: they see `stop`
        // within their read timeout and let it go; wait for that briefly.
        if let Some(bridge) = self.bridge.take() {
            let deadline = std::time::Instant::now() + Duration::from_secs(2);
            let mut bridge = bridge;
            loop {
                match Arc::try_unwrap(bridge) {
                    Ok(bridge) => {
                        drop(bridge);
                        break;
                    }
                    Err(again) if std::time::Instant::now() < deadline => {
                        bridge = again;
                        thread::sleep(Duration::from_millis(20));
                    }
                    Err(again) => {
                        drop(again);
                        break;
                    }
                }
            }
        }
    }
}

/// What the connections serve.
struct Site {
    panel: PathBuf,
    bridge: Option<Arc<Bridge>>,
    stop: Arc<AtomicBool>,
}

/// A request's head: the path and the WebSocket key, if an upgrade.
struct Request {
    path: String,
    websocket_key: Option<String>,
}

impl Site {
    fn serve(&self, mut stream: TcpStream) -> Result<()> {
        stream.set_read_timeout(Some(Duration::from_secs(10)))?;
        let Some(request) = read_request(&mut stream)? else {
            return Ok(());
        };
        match (&request.websocket_key, request.path.as_str(), &self.bridge) {
            (Some(key), "/ws", Some(bridge)) => self.websocket(stream, key, bridge),
            (Some(_), _, _) => respond(&mut stream, 404, "text/plain", b"no head to bridge to"),
            (None, path, _) => self.file(&mut stream, path),
        }
    }

    /// `path`'s file, `bridge.json`, or 404.
    fn file(&self, stream: &mut TcpStream, path: &str) -> Result<()> {
        let path = path.split(['?', '#']).next().unwrap_or_default();
        if path == "/bridge.json" {
            return match &self.bridge {
                Some(bridge) => {
                    let body = serde_json::json!({
                        "bridge": bridge.kind,
                        "name": bridge.name,
                        "ws": "/ws",
                    });
                    respond(stream, 200, "application/json", body.to_string().as_bytes())
                }
                None => respond(stream, 200, "application/json", NO_BRIDGE.as_bytes()),
            };
        }
        let file = match path.trim_start_matches('/') {
            "" => Some(self.panel.join("index.html")),
            vendor if vendor.starts_with("vendor/") => {
                let url = vendor.trim_start_matches("vendor/");
                VENDOR
                    .iter()
                    .find(|(u, _)| *u == url)
                    .map(|(_, file)| self.panel.join("node_modules").join(file))
            }
            name if !name.contains('/') && !name.starts_with('.') => {
                let file = self.panel.join(name);
                content_type(&file).is_some().then_some(file)
            }
            _ => None,
        };
        match file.and_then(|f| std::fs::read(&f).ok().map(|bytes| (f, bytes))) {
            Some((file, bytes)) => {
                let content_type = content_type(&file).unwrap_or("application/octet-stream");
                respond(stream, 200, content_type, &bytes)
            }
            None => respond(stream, 404, "text/plain", b"not found"),
        }
    }

    /// The WebSocket to the head: the page's messages to it, its bytes to
    /// the page (binary messages); a text message `{"gone": why}` when the
    /// head goes away.
    fn websocket(&self, mut stream: TcpStream, key: &str, bridge: &Arc<Bridge>) -> Result<()> {
        let accept = derive_accept_key(key.as_bytes());
        let head = format!(
            "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
             Sec-WebSocket-Accept: {accept}\r\n\r\n"
        );
        stream.write_all(head.as_bytes())?;
        stream.set_read_timeout(Some(Duration::from_millis(10)))?;
        stream.set_nodelay(true)?;
        let mut ws = WebSocket::from_raw_socket(stream, Role::Server, None);
        let notes = bridge.hub.join();
        loop {
            if self.stop.load(Ordering::Acquire) {
                let _ = ws.close(None);
                let _ = ws.flush();
                return Ok(());
            }
            match ws.read() {
                Ok(Message::Binary(bytes)) => bridge.write(&bytes)?,
                Ok(Message::Text(text)) => bridge.write(text.as_bytes())?,
                Ok(Message::Close(_)) => return Ok(()),
                Ok(_) => {}
                Err(tungstenite::Error::Io(e))
                    if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
                Err(_) => return Ok(()),
            }
            while let Ok(note) = notes.try_recv() {
                let message = match note {
                    Note::Bytes(bytes) => Message::Binary(bytes.into()),
                    Note::Gone(why) => {
                        Message::Text(serde_json::json!({ "gone": why }).to_string().into())
                    }
                };
                ws.write(message)?;
            }
            match ws.flush() {
                Ok(()) => {}
                Err(tungstenite::Error::Io(e))
                    if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
                Err(_) => return Ok(()),
            }
        }
    }
}

/// Reads a request's head; `None` for a connection that closed first.
fn read_request(stream: &mut TcpStream) -> Result<Option<Request>> {
    let mut buf = Vec::with_capacity(1024);
    let mut chunk = [0_u8; 1024];
    loop {
        let n = stream.read(&mut chunk)?;
        if n == 0 {
            return Ok(None);
        }
        buf.extend_from_slice(&chunk[..n]);
        let mut headers = [httparse::EMPTY_HEADER; 32];
        let mut request = httparse::Request::new(&mut headers);
        if request.parse(&buf)?.is_complete() {
            let header = |name: &str| {
                request
                    .headers
                    .iter()
                    .find(|h| h.name.eq_ignore_ascii_case(name))
                    .map(|h| String::from_utf8_lossy(h.value).into_owned())
            };
            let upgrade = header("upgrade").is_some_and(|u| u.eq_ignore_ascii_case("websocket"));
            let key = header("sec-websocket-key").filter(|_| upgrade);
            return Ok(Some(Request {
                path: request.path.unwrap_or("/").to_owned(),
                websocket_key: key,
            }));
        }
        if buf.len() > 64 * 1024 {
            anyhow::bail!("request head too long");
        }
    }
}

fn respond(stream: &mut TcpStream, status: u16, content_type: &str, body: &[u8]) -> Result<()> {
    let reason = match status {
        200 => "OK",
        404 => "Not Found",
        _ => "Error",
    };
    let head = format!(
        "HTTP/1.1 {status} {reason}\r\nContent-Type: {content_type}\r\nContent-Length: {}\r\n\
         Cache-Control: no-store\r\nConnection: close\r\n\r\n",
        body.len()
    );
    stream.write_all(head.as_bytes())?;
    stream.write_all(body)?;
    stream.flush()?;
    Ok(())
}
