//! The signature of a callback: `Chocmodal-Signature: t=<unix seconds>,v1=<hex>`, where
//! `<hex>` is the HMAC-SHA256 (RFC 2104) of the bytes `<t>.<body>` under a secret of the
//! job's tenant, one `v1=` per secret the tenant has (while a secret is being rotated,
//! a receiver that knows either accepts). Signing the time with the body lets receivers
//! refuse replays of an old delivery (compare `t` with their clock).
//!
//! HMAC is the `hmac` crate's (0.12, the release on the `digest` 0.10 that the `sha2`
//! of the content hashes uses); the tests check it against RFC 4231's vectors.

use hmac::{Hmac, Mac};
use sha2::Sha256;

/// Name of the signature header.
pub const SIGNATURE_HEADER: &str = "Chocmodal-Signature";

/// HMAC-SHA256 of `message` under `key` (RFC 2104; any key length).
pub fn hmac_sha256(key: &[u8], message: &[u8]) -> [u8; 32] {
    let mut mac = Hmac::<Sha256>::new_from_slice(key).expect("HMAC takes keys of any length");
    mac.update(message);
    mac.finalize().into_bytes().into()
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The header value for `body` sent at `unix_seconds`, signed with each of `secrets`.
pub fn signature_header(secrets: &[String], unix_seconds: i64, body: &[u8]) -> String {
    let mut signed = Vec::with_capacity(body.len() + 24);
    signed.extend_from_slice(unix_seconds.to_string().as_bytes());
    signed.push(b'.');
    signed.extend_from_slice(body);
    let mut header = format!("t={unix_seconds}");
    for secret in secrets {
        header.push_str(",v1=");
        header.push_str(&hex(&hmac_sha256(secret.as_bytes(), &signed)));
    }
    header
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unhex(text: &str) -> Vec<u8> {
        (0..text.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&text[i..i + 2], 16).unwrap())
            .collect()
    }

    /// RFC 4231, test cases 1, 2, 4 and 6 (a key longer than the block).
    #[test]
    fn hmac_matches_rfc_4231() {
        let cases: [(Vec<u8>, Vec<u8>, &str); 4] = [
            (
                vec![0x0b; 20],
                b"Hi There".to_vec(),
                "b0344c61d8db38535ca8afceaf0bf12b881dc200c9833da726e9376c2e32cff7",
            ),
            (
                b"Jefe".to_vec(),
                b"what do ya want for nothing?".to_vec(),
                "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843",
            ),
            (
                unhex("0102030405060708090a0b0c0d0e0f10111213141516171819"),
                vec![0xcd; 50],
                "82558a389a443c0ea4cc819899f2083a85f0faa3e578f8077a2e3ff46729665b",
            ),
            (
                vec![0xaa; 131],
                b"Test Using Larger Than Block-Size Key - Hash Key First".to_vec(),
                "60e431591ee0b67f0d8a26aacbf5b77f8e0bc6213728c5140546040f0ee37f54",
            ),
        ];
        for (key, message, expected) in cases {
            assert_eq!(
                hex(&hmac_sha256(&key, &message)),
                expected,
                "key of {} bytes",
                key.len()
            );
        }
    }

    #[test]
    fn the_header_signs_time_and_body_with_every_secret() {
        let secrets = vec![
            "first-secret-0123456789".to_owned(),
            "second-secret-012345678".to_owned(),
        ];
        let header = signature_header(&secrets, 1_700_000_000, b"{\"a\":1}");
        let parts: Vec<&str> = header.split(',').collect();
        assert_eq!(parts[0], "t=1700000000");
        assert_eq!(parts.len(), 3, "{header}");
        let expected = hex(&hmac_sha256(secrets[1].as_bytes(), b"1700000000.{\"a\":1}"));
        assert_eq!(parts[2], format!("v1={expected}"));
        assert_ne!(parts[1], parts[2]);
    }
}
