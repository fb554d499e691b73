//! The panel's web server, a thread a connection and one request each
//! (`Connection: close`, so that no kept-alive connection holds a thread):
//! the page's files, `vendor/…`, `bridge.json`, `GET /events` (the head's
//! bytes as server-sent events of hex digits, `gone` when it goes away),
//! `POST /send`.

use std::{
    io::{self, BufRead, BufReader, Read, Write},
    net::{Ipv4Addr, Ipv6Addr, SocketAddr, TcpListener, TcpStream},
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

use super::bridge::{Bridge, Note};
use super::{VENDOR, content_type};

/// `bridge.json` of a page served without a bridge (and of an exported
/// copy): the page offers Web Serial.
pub const NO_BRIDGE: &str = r#"{"bridge":null}"#;

/// The longest request head, and body, read; a client that sends neither
/// in this long is let go.
const HEAD_LIMIT: usize = 16 * 1024;
const BODY_LIMIT: u64 = 1 << 20;
const READ_TIMEOUT: Duration = Duration::from_secs(10);

/// The running server; dropping it stops it (and its bridge).
pub struct Server {
    stop: Arc<AtomicBool>,
    accepting: Option<thread::JoinHandle<()>>,
    pub address: SocketAddr,
}

impl Server {
    /// Serves `root`'s `panel/` on `listen`, bridged to `bridge`; a head
    /// that goes away is told on `stopped` too (the command then ends,
    /// saying so).
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
        if let Some(bridge) = &bridge {
            let notes = bridge.hub.join();
            thread::spawn(move || {
                if let Some(Note::Gone(why)) = notes.iter().find(|n| matches!(n, Note::Gone(_))) {
                    let _ = stopped.send(format!("the head went away ({why})"));
                }
            });
        }
        let panel = root.join("panel");
        let stop = Arc::new(AtomicBool::new(false));
        let stopping = Arc::clone(&stop);
        let accepting = thread::spawn(move || {
            for stream in listener.incoming() {
                if stopping.load(Ordering::Acquire) {
                    break;
                }
                let Ok(stream) = stream else { continue };
                let (panel, bridge) = (panel.clone(), bridge.clone());
                thread::spawn(move || serve(stream, &panel, bridge));
            }
        });
        Ok(Self {
            stop,
            accepting: Some(accepting),
            address,
        })
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        // The accepting thread holds the bridge; a request holds it while
        // it is answered, an event stream not at all. A connection of our
        // own wakes the thread to see it is told to stop.
        self.stop.store(true, Ordering::Release);
        let mut wake = self.address;
        if wake.ip().is_unspecified() {
            wake.set_ip(match wake {
                SocketAddr::V4(_) => Ipv4Addr::LOCALHOST.into(),
                SocketAddr::V6(_) => Ipv6Addr::LOCALHOST.into(),
            });
        }
        if TcpStream::connect(wake).is_ok()
            && let Some(accepting) = self.accepting.take()
        {
            let _ = accepting.join();
        }
    }
}

/// One request on `stream`, answered; the connection then closes.
fn serve(stream: TcpStream, panel: &Path, bridge: Option<Arc<Bridge>>) -> io::Result<()> {
    stream.set_nodelay(true)?;
    stream.set_read_timeout(Some(READ_TIMEOUT))?;
    let mut out = stream.try_clone()?;
    let mut reader = BufReader::new(stream);
    let mut head = Vec::new();
    while !(head.ends_with(b"\r\n\r\n") || head.ends_with(b"\n\n")) {
        let limit = (HEAD_LIMIT - head.len()) as u64;
        if limit == 0 || (&mut reader).take(limit).read_until(b'\n', &mut head)? == 0 {
            break;
        }
    }
    let mut headers = [httparse::EMPTY_HEADER; 64];
    let mut request = httparse::Request::new(&mut headers);
    let parsed = matches!(request.parse(&head), Ok(httparse::Status::Complete(_)));
    let length = request
        .headers
        .iter()
        .find(|h| h.name.eq_ignore_ascii_case("content-length"))
        .and_then(|h| std::str::from_utf8(h.value).ok()?.trim().parse().ok())
        .unwrap_or(0u64);
    let mut body = Vec::new();
    reader.take(length.min(BODY_LIMIT)).read_to_end(&mut body)?;
    let url = request.path.unwrap_or("/");
    let path = url.split(['?', '#']).next().unwrap_or(url);
    let text = |status, body: &str| (status, "text/plain; charset=utf-8", body.into());
    let (status, kind, reply) = match (parsed, request.method.unwrap_or(""), path, bridge) {
        (false, ..) => text("400 Bad Request", "not a whole HTTP request"),
        (_, "GET", "/events", Some(bridge)) => {
            let notes = bridge.hub.join();
            drop(bridge);
            return events(out, &notes);
        }
        (_, "POST", "/send", Some(bridge)) => match bridge.write(&body) {
            Ok(()) => text("200 OK", "sent"),
            Err(e) => text("503 Service Unavailable", &format!("not sent: {e:#}")),
        },
        (_, "GET", "/bridge.json", bridge) => {
            let body = bridge.map_or_else(
                || NO_BRIDGE.to_owned(),
                |b| serde_json::json!({"bridge": b.kind, "name": b.name}).to_string(),
            );
            ("200 OK", "application/json", body.into_bytes())
        }
        (_, "GET", path, _) => match page_file(panel, path) {
            Some((bytes, kind)) => ("200 OK", kind, bytes),
            None => text("404 Not Found", "not found"),
        },
        _ => text("405 Method Not Allowed", "the page is static: GET it"),
    };
    answer(&mut out, status, kind, Some(&reply))
}

/// A response, after which the connection closes: `body` whole, or `None`
/// when a stream follows. Nothing is cached (the page's files change as
/// the panel is worked on).
fn answer(out: &mut TcpStream, status: &str, kind: &str, body: Option<&[u8]>) -> io::Result<()> {
    let length = body.map_or(String::new(), |b| {
        format!("Content-Length: {}\r\n", b.len())
    });
    write!(
        out,
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\n{length}Cache-Control: no-store\r\n\
         Connection: close\r\n\r\n"
    )?;
    out.write_all(body.unwrap_or_default())?;
    out.flush()
}

/// The file `path` names: the page's own (in `panel/`), or a dependency's.
fn page_file(panel: &Path, path: &str) -> Option<(Vec<u8>, &'static str)> {
    let file: PathBuf = match path.trim_start_matches('/') {
        "" => panel.join("index.html"),
        vendor if vendor.starts_with("vendor/") => {
            let url = vendor.trim_start_matches("vendor/");
            let (_, file) = VENDOR.iter().find(|(u, _)| *u == url)?;
            panel.join("node_modules").join(file)
        }
        name if !name.contains('/') && !name.starts_with('.') => panel.join(name),
        _ => return None,
    };
    Some((std::fs::read(&file).ok()?, content_type(&file)?))
}

/// The event stream: the head's bytes, until it goes away or the page does.
fn events(mut out: TcpStream, notes: &mpsc::Receiver<Note>) -> io::Result<()> {
    answer(&mut out, "200 OK", "text/event-stream", None)?;
    for note in notes {
        match note {
            Note::Bytes(bytes) => write!(out, "data: {}\n\n", hex::encode(&bytes))?,
            Note::Gone(why) => {
                write!(out, "event: gone\ndata: {why}\n\n")?;
                return out.flush();
            }
        }
        out.flush()?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The whole reply to `request`, read until the server closes.
    fn ask(address: SocketAddr, request: &str) -> String {
        let mut stream = TcpStream::connect(address).unwrap();
        stream
            .set_read_timeout(Some(Duration::from_secs(5)))
            .unwrap();
        stream.write_all(request.as_bytes()).unwrap();
        let mut reply = String::new();
        stream.read_to_string(&mut reply).unwrap();
        reply
    }

    #[test]
    fn idle_connections_hold_no_request_up_and_every_answer_closes_its_own() {
        let (stopped, _) = mpsc::channel();
        let root = crate::project::root();
        let server = Server::start(&root, "127.0.0.1:0".parse().unwrap(), None, stopped).unwrap();
        // A browser opens connections ahead of its requests and may leave
        // some idle.
        let idle: Vec<_> = (0..16)
            .map(|_| TcpStream::connect(server.address).unwrap())
            .collect();
        let reply = ask(
            server.address,
            "GET /bridge.json HTTP/1.1\r\nHost: a\r\n\r\n",
        );
        assert!(reply.starts_with("HTTP/1.1 200 OK\r\n"), "{reply}");
        assert!(reply.contains("\r\nConnection: close\r\n"), "{reply}");
        assert!(reply.ends_with(&format!("\r\n\r\n{NO_BRIDGE}")), "{reply}");
        for (request, status) in [
            ("POST /send HTTP/1.1\r\nContent-Length: 3\r\n\r\nabc", "405"),
            ("GET /../Cargo.toml HTTP/1.1\r\n\r\n", "404"),
            ("GET /vendor/../../Cargo.toml HTTP/1.1\r\n\r\n", "404"),
            ("a request?\r\n\r\n", "400"),
        ] {
            let reply = ask(server.address, request);
            assert!(
                reply.starts_with(&format!("HTTP/1.1 {status} ")),
                "{request:?}: {reply}"
            );
        }
        drop(idle);
        drop(server);
    }
}
