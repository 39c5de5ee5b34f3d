//! A `Vec<u8>` field written and read as a byte string (`#[serde(with = "bytes")]`). In
//! postcard a byte string is the same bytes as a sequence of u8 (a length, then the
//! bytes), so saved states keep their format; it is read in one copy instead of one call
//! per byte (a model's state is kilobytes, and every restore reads it).

use std::fmt;

use serde::de::{self, SeqAccess, Visitor};
use serde::{Deserializer, Serializer};

/// Writes `bytes` as a byte string.
pub fn serialize<S: Serializer>(bytes: &[u8], serializer: S) -> Result<S::Ok, S::Error> {
    serializer.serialize_bytes(bytes)
}

/// Reads a byte string (or, from a format that writes them so, a sequence of u8).
pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Vec<u8>, D::Error> {
    deserializer.deserialize_byte_buf(ByteString)
}

struct ByteString;

impl<'de> Visitor<'de> for ByteString {
    type Value = Vec<u8>;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a byte string")
    }

    fn visit_bytes<E: de::Error>(self, bytes: &[u8]) -> Result<Vec<u8>, E> {
        Ok(bytes.to_vec())
    }

    fn visit_byte_buf<E: de::Error>(self, bytes: Vec<u8>) -> Result<Vec<u8>, E> {
        Ok(bytes)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<u8>, A::Error> {
        let mut bytes = Vec::with_capacity(seq.size_hint().unwrap_or(0).min(1 << 16));
        while let Some(b) = seq.next_element()? {
            bytes.push(b);
        }
        Ok(bytes)
    }
}

#[cfg(test)]
mod tests {
    #[derive(serde::Serialize, serde::Deserialize, PartialEq, Debug)]
    struct AsBytes(#[serde(with = "super")] Vec<u8>);

    #[test]
    fn the_bytes_are_those_of_a_sequence_of_u8() {
        for n in [0, 1, 127, 128, 300, 70_000] {
            let v: Vec<u8> = (0..n).map(|i| (i * 7 % 251) as u8).collect();
            let as_seq = postcard::to_stdvec(&v).unwrap();
            let as_bytes = postcard::to_stdvec(&AsBytes(v.clone())).unwrap();
            assert_eq!(as_bytes, as_seq, "{n} bytes");
            assert_eq!(
                postcard::from_bytes::<AsBytes>(&as_seq).unwrap(),
                AsBytes(v)
            );
        }
        // Truncated: refused as a sequence would be.
        let whole = postcard::to_stdvec(&vec![5u8; 10]).unwrap();
        assert!(postcard::from_bytes::<AsBytes>(&whole[..5]).is_err());
    }
}
