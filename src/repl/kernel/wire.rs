//! The Jupyter wire protocol (messaging 5.3): multipart ZeroMQ messages
//! `[identities…, "<IDS|MSG>", signature, header, parent_header, metadata, content, buffers…]`,
//! signed with HMAC-SHA256 over the four JSON parts with the connection file's key. A message
//! whose signature is missing or wrong is refused here and never reaches the session.

use hmac::{Hmac, Mac};
use serde_json::{json, Value};
use sha2::Sha256;
use std::time::{SystemTime, UNIX_EPOCH};

const DELIMITER: &[u8] = b"<IDS|MSG>";

/// The protocol version this kernel speaks.
pub const PROTOCOL_VERSION: &str = "5.3";

/// The signing key of one kernel start (from its connection file).
#[derive(Clone)]
pub struct Key(Vec<u8>);

impl Key {
    /// A key from the connection file: it must not be empty (unsigned messages would then be
    /// accepted) and the scheme must be hmac-sha256.
    pub fn new(key: &str, scheme: &str) -> Result<Self, String> {
        if scheme != "hmac-sha256" {
            return Err(format!(
                "the connection file asks for signature scheme \"{scheme}\"; this kernel signs with \"hmac-sha256\" only"
            ));
        }
        if key.is_empty() {
            return Err("the connection file has an empty key, which would let any local process run code in this kernel; start the kernel from Jupyter, which writes a fresh key for each start".into());
        }
        Ok(Key(key.as_bytes().to_vec()))
    }

    fn mac(&self) -> Hmac<Sha256> {
        // HMAC takes a key of any length.
        Hmac::<Sha256>::new_from_slice(&self.0).expect("HMAC accepts keys of any length")
    }

    /// The hex signature of the four parts.
    pub fn sign(&self, parts: &[&[u8]]) -> String {
        let mut mac = self.mac();
        for p in parts {
            mac.update(p);
        }
        hex(&mac.finalize().into_bytes())
    }

    /// Whether `signature` (hex) signs the four parts; compared in constant time.
    pub fn verify(&self, signature: &[u8], parts: &[&[u8]]) -> bool {
        let Some(bytes) = unhex(signature) else {
            return false;
        };
        let mut mac = self.mac();
        for p in parts {
            mac.update(p);
        }
        mac.verify_slice(&bytes).is_ok()
    }
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn unhex(s: &[u8]) -> Option<Vec<u8>> {
    if !s.len().is_multiple_of(2) {
        return None;
    }
    s.chunks(2)
        .map(|c| u8::from_str_radix(std::str::from_utf8(c).ok()?, 16).ok())
        .collect()
}

/// A message received or to send.
#[derive(Debug, Clone)]
pub struct Message {
    /// The ZeroMQ routing identities (ROUTER sockets) or topic (IOPub).
    pub identities: Vec<Vec<u8>>,
    pub header: Value,
    pub parent_header: Value,
    pub metadata: Value,
    pub content: Value,
}

impl Message {
    /// The message type named in the header.
    pub fn msg_type(&self) -> &str {
        self.header["msg_type"].as_str().unwrap_or("")
    }

    /// Parse and verify a multipart message; `Err` says why it was refused.
    pub fn decode(frames: Vec<Vec<u8>>, key: &Key) -> Result<Message, String> {
        let at = frames
            .iter()
            .position(|f| f == DELIMITER)
            .ok_or("no <IDS|MSG> delimiter")?;
        if frames.len() < at + 6 {
            return Err("too few frames after the delimiter".into());
        }
        let parts: Vec<&[u8]> = frames[at + 2..at + 6]
            .iter()
            .map(|f| f.as_slice())
            .collect();
        if !key.verify(&frames[at + 1], &parts) {
            return Err("missing or wrong signature".into());
        }
        let json = |b: &[u8], what: &str| -> Result<Value, String> {
            serde_json::from_slice(b).map_err(|e| format!("{what} is not JSON: {e}"))
        };
        Ok(Message {
            identities: frames[..at].to_vec(),
            header: json(parts[0], "header")?,
            parent_header: json(parts[1], "parent header")?,
            metadata: json(parts[2], "metadata")?,
            content: json(parts[3], "content")?,
        })
    }

    /// The frames of this message, signed.
    pub fn encode(&self, key: &Key) -> Vec<Vec<u8>> {
        let parts: Vec<Vec<u8>> = [
            &self.header,
            &self.parent_header,
            &self.metadata,
            &self.content,
        ]
        .iter()
        .map(|v| serde_json::to_vec(v).unwrap_or_else(|_| b"{}".to_vec()))
        .collect();
        let refs: Vec<&[u8]> = parts.iter().map(|p| p.as_slice()).collect();
        let mut frames = self.identities.clone();
        frames.push(DELIMITER.to_vec());
        frames.push(key.sign(&refs).into_bytes());
        frames.extend(parts);
        frames
    }
}

/// Headers of the messages this kernel sends.
pub struct Headers {
    session: String,
}

impl Headers {
    /// Headers for a kernel session with a fresh id.
    pub fn new() -> Self {
        Headers { session: uuid() }
    }

    /// A reply or broadcast of type `msg_type` to `parent` (its header and identities).
    pub fn make(&self, parent: Option<&Message>, msg_type: &str, content: Value) -> Message {
        Message {
            identities: parent.map(|p| p.identities.clone()).unwrap_or_default(),
            header: json!({
                "msg_id": uuid(),
                "session": self.session,
                "username": "swimlab",
                "date": now_iso8601(),
                "msg_type": msg_type,
                "version": PROTOCOL_VERSION,
            }),
            parent_header: parent.map_or(json!({}), |p| p.header.clone()),
            metadata: json!({}),
            content,
        }
    }
}

/// A random (version 4) UUID.
pub fn uuid() -> String {
    let mut b = [0u8; 16];
    if getrandom::fill(&mut b).is_err() {
        // Message ids need only be unique: fall back on the clock and a counter.
        use std::sync::atomic::{AtomicU64, Ordering};
        static COUNT: AtomicU64 = AtomicU64::new(0);
        let n = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos() as u64);
        b[..8].copy_from_slice(&n.to_le_bytes());
        b[8..].copy_from_slice(&COUNT.fetch_add(1, Ordering::Relaxed).to_le_bytes());
    }
    b[6] = (b[6] & 0x0f) | 0x40;
    b[8] = (b[8] & 0x3f) | 0x80;
    let h = hex(&b);
    format!(
        "{}-{}-{}-{}-{}",
        &h[..8],
        &h[8..12],
        &h[12..16],
        &h[16..20],
        &h[20..]
    )
}

/// The time now as ISO 8601 in UTC with microseconds (the header's `date`).
pub fn now_iso8601() -> String {
    let d = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .unwrap_or_default();
    let secs = d.as_secs() as i64;
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    // Civil date from days since 1970-01-01 (Howard Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}.{:06}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60,
        d.subsec_micros()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_signed_message_round_trips_and_a_tampered_one_is_refused() {
        let key = Key::new("secret", "hmac-sha256").unwrap();
        let h = Headers::new();
        let m = h.make(None, "execute_request", json!({"code": "1 + 1"}));
        let frames = m.encode(&key);
        let back = Message::decode(frames.clone(), &key).unwrap();
        assert_eq!(back.content["code"], "1 + 1");
        let mut tampered = frames.clone();
        let last = tampered.len() - 1;
        tampered[last] = br#"{"code": "2 + 2"}"#.to_vec();
        assert!(Message::decode(tampered, &key).is_err());
        let other = Key::new("other", "hmac-sha256").unwrap();
        assert!(Message::decode(frames, &other).is_err());
    }

    #[test]
    fn the_signature_is_hmac_sha256_of_the_four_parts() {
        // RFC 4231 test case 2: key "Jefe", data "what do ya want for nothing?".
        let key = Key::new("Jefe", "hmac-sha256").unwrap();
        assert_eq!(
            key.sign(&[b"what do ya want ", b"for nothing?"]),
            "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843"
        );
    }

    #[test]
    fn dates_and_ids_are_well_formed() {
        let d = now_iso8601();
        assert_eq!(d.len(), 27, "{d}");
        assert!(d.starts_with("20") && d.ends_with('Z'));
        let u = uuid();
        assert_eq!(u.len(), 36);
        assert_eq!(&u[14..15], "4");
    }

    #[test]
    fn empty_keys_and_other_schemes_are_refused() {
        assert!(Key::new("", "hmac-sha256").is_err());
        assert!(Key::new("k", "hmac-md5").is_err());
    }
}
