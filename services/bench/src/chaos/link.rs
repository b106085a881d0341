//! A link that can be cut: a TCP relay between some roles and the router, on its own
//! loopback port. While it is cut it reads nothing and connects nothing, as a cable
//! pulled out or a switch that drops everything: bytes wait in the kernel's buffers,
//! Zenoh's keep-alives do not cross, and a cut longer than the session's lease ends the
//! session at both ends, as a real partition does. Healed, it carries on; connections
//! the endpoints gave up on meanwhile end, and the ones they opened meanwhile go through.
//!
//! A network namespace would cut the same way, but needs root; the relay needs nothing,
//! and in roam's star (every role a client of one router) a role's link is the only
//! way to every other role.

use std::net::SocketAddr;

use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::tcp::{OwnedReadHalf, OwnedWriteHalf};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::watch;
use tokio::task::JoinHandle;

/// A cuttable relay from its own loopback port to `upstream`.
#[derive(Debug)]
pub struct Link {
    port: u16,
    cut: watch::Sender<bool>,
    accept: JoinHandle<()>,
}

impl Link {
    /// Listens on a free loopback port and relays each connection to `upstream`.
    pub async fn start(upstream: SocketAddr) -> std::io::Result<Link> {
        let listener = TcpListener::bind(("127.0.0.1", 0)).await?;
        let port = listener.local_addr()?.port();
        let (cut, _) = watch::channel(false);
        let cuts = cut.clone();
        let accept = tokio::spawn(async move {
            while let Ok((inbound, _)) = listener.accept().await {
                tokio::spawn(relay(inbound, upstream, cuts.subscribe()));
            }
        });
        Ok(Link { port, cut, accept })
    }

    /// The Zenoh endpoint the roles behind this link connect to.
    pub fn endpoint(&self) -> String {
        format!("tcp/127.0.0.1:{}", self.port)
    }

    /// From now on nothing crosses.
    pub fn cut(&self) {
        self.cut.send_replace(true);
    }

    /// From now on everything crosses again.
    pub fn heal(&self) {
        self.cut.send_replace(false);
    }
}

impl Drop for Link {
    fn drop(&mut self) {
        self.accept.abort();
    }
}

/// One connection: connected upstream once the link is whole, then both ways pumped.
async fn relay(inbound: TcpStream, upstream: SocketAddr, mut cut: watch::Receiver<bool>) {
    if !until(&mut cut, false).await {
        return;
    }
    let Ok(outbound) = TcpStream::connect(upstream).await else {
        // The router is down: the client sees its connection end and tries again.
        return;
    };
    let _ = inbound.set_nodelay(true);
    let _ = outbound.set_nodelay(true);
    let (in_read, in_write) = inbound.into_split();
    let (out_read, out_write) = outbound.into_split();
    let up = tokio::spawn(pump(in_read, out_write, cut.clone()));
    pump(out_read, in_write, cut).await;
    let _ = up.await;
}

/// Waits until the link is cut (`true`) or whole; `false` when the link is gone. (The
/// channel's guard is dropped here, so the relay's futures stay `Send`.)
async fn until(cut: &mut watch::Receiver<bool>, state: bool) -> bool {
    cut.wait_for(|c| *c == state).await.is_ok()
}

/// Copies `from` to `to` while the link is whole; stops reading while it is cut.
async fn pump(mut from: OwnedReadHalf, mut to: OwnedWriteHalf, mut cut: watch::Receiver<bool>) {
    let mut buf = vec![0u8; 64 * 1024];
    loop {
        if !until(&mut cut, false).await {
            return;
        }
        tokio::select! {
            read = from.read(&mut buf) => match read {
                Ok(0) | Err(_) => {
                    let _ = to.shutdown().await;
                    return;
                }
                Ok(n) => {
                    if to.write_all(&buf[..n]).await.is_err() {
                        return;
                    }
                }
            },
            // Reading is cancel-safe: a read cut short lost nothing.
            _ = until(&mut cut, true) => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    async fn echo_server() -> SocketAddr {
        let listener = TcpListener::bind(("127.0.0.1", 0)).await.expect("bind");
        let addr = listener.local_addr().expect("addr");
        tokio::spawn(async move {
            while let Ok((mut s, _)) = listener.accept().await {
                tokio::spawn(async move {
                    let mut buf = [0u8; 1024];
                    while let Ok(n) = s.read(&mut buf).await {
                        if n == 0 || s.write_all(&buf[..n]).await.is_err() {
                            break;
                        }
                    }
                });
            }
        });
        addr
    }

    async fn echo(stream: &mut TcpStream, text: &[u8], within: Duration) -> Option<Vec<u8>> {
        stream.write_all(text).await.ok()?;
        let mut got = vec![0u8; text.len()];
        tokio::time::timeout(within, stream.read_exact(&mut got))
            .await
            .ok()?
            .ok()?;
        Some(got)
    }

    #[tokio::test]
    async fn a_cut_link_carries_nothing_until_it_heals() {
        let link = Link::start(echo_server().await).await.expect("link");
        let port = link.endpoint().rsplit(':').next().expect("port").to_owned();
        let mut stream = TcpStream::connect(format!("127.0.0.1:{port}"))
            .await
            .expect("connect");
        let long = Duration::from_secs(5);
        assert_eq!(
            echo(&mut stream, b"hello", long).await.as_deref(),
            Some(&b"hello"[..])
        );
        link.cut();
        assert_eq!(
            echo(&mut stream, b"lost?", Duration::from_millis(300)).await,
            None,
            "bytes crossed a cut link"
        );
        // A connection opened while cut waits for the heal.
        let mut late = TcpStream::connect(format!("127.0.0.1:{port}"))
            .await
            .expect("accepted while cut");
        link.heal();
        // What waited in the buffers arrives, nothing is lost on a live connection.
        let mut rest = [0u8; 5];
        tokio::time::timeout(long, stream.read_exact(&mut rest))
            .await
            .expect("the held bytes after the heal")
            .expect("read");
        assert_eq!(&rest, b"lost?");
        assert_eq!(
            echo(&mut late, b"again", long).await.as_deref(),
            Some(&b"again"[..])
        );
    }
}
