//! Which host a URL printed for a server should carry: the address it listens on, or, for an
//! unspecified one (`--bind 0.0.0.0`), an address other machines can reach (never 127.0.0.1, which
//! names each reader's own machine).

use std::net::{IpAddr, Ipv4Addr, Ipv6Addr, UdpSocket};

/// The host part of a URL for `ip`: `[v6]` bracketed, v4 as is.
#[must_use]
pub fn url_host(ip: IpAddr) -> String {
    match ip {
        IpAddr::V4(v4) => v4.to_string(),
        IpAddr::V6(v6) => format!("[{v6}]"),
    }
}

/// The host a URL on this machine carries for a server bound to `ip`: `ip` itself, or loopback for
/// an unspecified address (it listens there too).
#[must_use]
pub fn local_host(ip: IpAddr) -> String {
    match ip {
        IpAddr::V4(v4) if v4.is_unspecified() => url_host(IpAddr::V4(Ipv4Addr::LOCALHOST)),
        IpAddr::V6(v6) if v6.is_unspecified() => url_host(IpAddr::V6(Ipv6Addr::LOCALHOST)),
        _ => url_host(ip),
    }
}

/// The host a URL for other machines carries for a server bound to `ip`: `ip` itself, or for an
/// unspecified address this machine's outward address ([`outward_ip`]), else its name; None when
/// neither is known (no route out, no name).
#[must_use]
pub fn network_host(ip: IpAddr) -> Option<String> {
    if !ip.is_unspecified() {
        return Some(url_host(ip));
    }
    outward_ip(ip.is_ipv6()).map(url_host).or_else(this_hostname)
}

/// The address this machine would send from to the rest of the network: a UDP socket "connected"
/// to a documentation address (192.0.2.1, 2001:db8::1; nothing is sent, the kernel only picks a
/// route), then its local address. None without a route, or when that is loopback.
#[must_use]
pub fn outward_ip(v6: bool) -> Option<IpAddr> {
    let (bind, to): (IpAddr, IpAddr) = if v6 {
        (IpAddr::V6(Ipv6Addr::UNSPECIFIED), IpAddr::V6(Ipv6Addr::new(0x2001, 0xdb8, 0, 0, 0, 0, 0, 1)))
    } else {
        (IpAddr::V4(Ipv4Addr::UNSPECIFIED), IpAddr::V4(Ipv4Addr::new(192, 0, 2, 1)))
    };
    let socket = UdpSocket::bind((bind, 0)).ok()?;
    socket.connect((to, 9)).ok()?;
    let ip = socket.local_addr().ok()?.ip();
    (!ip.is_unspecified() && !ip.is_loopback()).then_some(ip)
}

/// This machine's name (Linux: /proc/sys/kernel/hostname), lower case; None when it cannot be read
/// or is not a plain DNS name (letters, digits, `-` and `.`).
#[must_use]
pub fn this_hostname() -> Option<String> {
    use std::io::Read as _;
    let mut text = String::new();
    crate::io::files::open_input(std::path::Path::new("/proc/sys/kernel/hostname"))
        .ok()?
        .take(256)
        .read_to_string(&mut text)
        .ok()?;
    let name = text.trim().to_ascii_lowercase();
    let plain = !name.is_empty()
        && name != "localhost"
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '.');
    plain.then_some(name)
}

/// The Rerun web viewer's page at `host:web_port`, showing the stream at `host:grpc_port` (and,
/// with `history_port`, first the session so far from `http://host:history_port/history.rrd`), in
/// its dark theme (each URL percent-encoded in a `url=` of the page's query).
#[must_use]
pub fn web_viewer_page(host: &str, web_port: u16, grpc_port: u16, history_port: Option<u16>) -> String {
    let encode = |url: String| {
        url.replace(':', "%3A").replace('/', "%2F").replace('+', "%2B").replace('[', "%5B").replace(']', "%5D")
    };
    let history = history_port
        .map_or_else(String::new, |p| format!("url={}&", encode(format!("http://{host}:{p}{HISTORY_PATH}"))));
    let stream = encode(format!("rerun+http://{host}:{grpc_port}/proxy"));
    format!("http://{host}:{web_port}/?{history}url={stream}&theme=dark")
}

/// Where a live session's class page serves the session so far as one recording.
pub const HISTORY_PATH: &str = "/history.rrd";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn urls_name_a_host_others_can_reach() {
        assert_eq!(local_host("0.0.0.0".parse().expect("ip")), "127.0.0.1");
        assert_eq!(local_host("::".parse().expect("ip")), "[::1]");
        assert_eq!(network_host("192.168.1.5".parse().expect("ip")).as_deref(), Some("192.168.1.5"));
        if let Some(h) = network_host("0.0.0.0".parse().expect("ip")) {
            assert!(h != "127.0.0.1" && h != "0.0.0.0", "{h}");
        }
        assert_eq!(
            web_viewer_page("[::1]", 9091, 9092, None),
            "http://[::1]:9091/?url=rerun%2Bhttp%3A%2F%2F%5B%3A%3A1%5D%3A9092%2Fproxy&theme=dark"
        );
    }
}
