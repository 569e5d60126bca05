//! Properties of the readers over arbitrary bytes, mutated valid files and headers assembled
//! from right and wrong parts: no panic, and either an input error or exactly the declared
//! number of elements.

use proptest::prelude::*;

use super::tests::{dict, file, p};
use super::*;

/// The readers' contract on any input: no panic, and either an input error or exactly the
/// number of elements the header declares, with the data exactly as long as they need.
fn contract(bytes: &[u8]) -> std::result::Result<(), TestCaseError> {
    let results = [
        decode_f32(p(), bytes).map(|v| (v.len(), true)),
        decode_u32(p(), bytes).map(|v| (v.len(), true)),
        decode_f32_shaped(p(), bytes).map(|(s, v)| {
            assert_eq!(s.iter().product::<usize>(), v.len());
            (v.len(), false)
        }),
    ];
    for r in results {
        match r {
            Ok((n, one_d)) => {
                let (h, at) = parse_header(p(), bytes).expect("a file read has a header");
                prop_assert_eq!(n, h.elements());
                prop_assert_eq!(bytes.len() - at, 4 * n);
                if one_d {
                    prop_assert_eq!(h.shape.clone(), vec![n]);
                }
            }
            Err(e) => prop_assert!(matches!(e, Error::InvalidInput(_)), "{e:?}"),
        }
    }
    Ok(())
}

/// A valid file: version, dtype, shape, order and data all drawn.
fn valid_file() -> impl Strategy<Value = Vec<u8>> {
    (
        1u8..=3,
        prop::sample::select(vec!["<f4", "<i4", "<u4"]),
        prop::collection::vec(0usize..6, 1..3),
        any::<bool>(),
        any::<u64>(),
    )
        .prop_map(|(version, descr, shape, fortran, seed)| {
            let n: usize = shape.iter().product();
            let dims = match shape.as_slice() {
                [a] => format!("({a},)"),
                s => format!(
                    "({})",
                    s.iter()
                        .map(|d| d.to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            };
            let fortran = if fortran { "True" } else { "False" };
            let data: Vec<u8> = (0..4 * n as u64)
                .map(|i| (seed.rotate_left(i as u32 % 64) ^ i) as u8)
                .collect();
            file(version, &dict(&format!("'{descr}'"), fortran, &dims), &data)
        })
}

/// A header assembled from right and wrong parts, with the data sometimes as long as its
/// shape needs.
fn assembled_file() -> impl Strategy<Value = Vec<u8>> {
    // Right parts three times as often as wrong ones, so that some files are read.
    let descr = prop_oneof![
        3 => prop::sample::select(vec!["'<f4'", "'<i4'", "'<u4'"]),
        1 => prop::sample::select(vec![
            "'>f4'", "'<f8'", "[('a', '<f4')]", "[('a', '<f4', (2,))]", "4", "None", "'<f4",
            "'|b1'",
        ]),
    ];
    let fortran = prop_oneof![
        3 => prop::sample::select(vec!["False", "True"]),
        1 => prop::sample::select(vec!["0", "'True'", "Flase"]),
    ];
    let size = prop_oneof![
        3 => prop::sample::select(vec!["0", "1", "2", "3", "7", "2L", "+3"]),
        1 => prop::sample::select(vec![
            "4611686018427387904", "18446744073709551615", "18446744073709551616",
            "4294967296", "-1", "2.5", "x", "()",
        ]),
    ];
    let shape = (prop::collection::vec(size, 0..4), any::<bool>(), 0u8..10).prop_map(
        |(sizes, trailing, form)| match form {
            0 => format!("[{}]", sizes.join(", ")),
            1 => sizes.join(", "),
            _ if trailing || sizes.len() <= 1 => format!("({},)", sizes.join(", ")),
            _ => format!("({})", sizes.join(", ")),
        },
    );
    (
        descr,
        fortran,
        shape,
        prop::option::weighted(0.2, any::<prop::sample::Index>()),
        prop::bool::weighted(0.2),
        1u8..=3,
        prop::option::weighted(0.3, 0usize..40),
    )
        .prop_flat_map(|(descr, fortran, shape, drop, extra, version, data_len)| {
            let mut entries = vec![
                format!("'descr': {descr}"),
                format!("'fortran_order': {fortran}"),
                format!("'shape': {shape}"),
            ];
            if let Some(i) = drop {
                entries.remove(i.index(3));
            }
            if extra {
                entries.push("'extra': ()".into());
            }
            (Just(entries).prop_shuffle(), Just(version), Just(data_len))
        })
        .prop_map(|(entries, version, data_len)| {
            let text = format!("{{{}, }}", entries.join(", "));
            let header_only = file(version, &text, &[]);
            // Exactly the declared length where that is small, to reach the readers' success.
            let len = data_len.unwrap_or_else(|| match parse_header(p(), &header_only) {
                Ok((h, _)) if h.elements() <= 64 => 4 * h.elements(),
                _ => 8,
            });
            file(version, &text, &vec![0x3f; len])
        })
}

/// One edit of a file: set, flip, insert or remove a byte, or cut the file short.
#[derive(Debug, Clone)]
enum Mutation {
    Set(prop::sample::Index, u8),
    Flip(prop::sample::Index, u8),
    Insert(prop::sample::Index, u8),
    Remove(prop::sample::Index),
    Truncate(prop::sample::Index),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let i = any::<prop::sample::Index>;
    prop_oneof![
        (i(), any::<u8>()).prop_map(|(i, b)| Mutation::Set(i, b)),
        (i(), 1u8..=255).prop_map(|(i, b)| Mutation::Flip(i, b)),
        (i(), any::<u8>()).prop_map(|(i, b)| Mutation::Insert(i, b)),
        i().prop_map(Mutation::Remove),
        i().prop_map(Mutation::Truncate),
    ]
}

fn mutate(mut b: Vec<u8>, edits: &[Mutation]) -> Vec<u8> {
    for m in edits {
        if b.is_empty() {
            break;
        }
        match m {
            Mutation::Set(i, v) => {
                let i = i.index(b.len());
                b[i] = *v;
            }
            Mutation::Flip(i, v) => {
                let i = i.index(b.len());
                b[i] ^= *v;
            }
            Mutation::Insert(i, v) => b.insert(i.index(b.len() + 1), *v),
            Mutation::Remove(i) => {
                b.remove(i.index(b.len()));
            }
            Mutation::Truncate(i) => b.truncate(i.index(b.len())),
        }
    }
    b
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 2000,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn arbitrary_bytes_are_refused_or_read_whole(bytes in prop::collection::vec(any::<u8>(), 0..300)) {
        contract(&bytes)?;
    }

    #[test]
    fn arbitrary_bytes_after_a_preamble_are_refused_or_read_whole(
        version in 0u8..5,
        len in any::<u16>(),
        tail in prop::collection::vec(any::<u8>(), 0..300),
    ) {
        let mut bytes = MAGIC.to_vec();
        bytes.extend_from_slice(&[version, 0]);
        bytes.extend_from_slice(&(len % 320).to_le_bytes());
        bytes.extend_from_slice(&tail);
        contract(&bytes)?;
    }

    #[test]
    fn valid_files_are_read_whole(bytes in valid_file()) {
        let (h, _) = parse_header(p(), &bytes).unwrap();
        let n = decode_f32_shaped(p(), &bytes).map(|(_, v)| v.len());
        if h.descr == "<f4" && !h.fortran_order {
            prop_assert_eq!(n.unwrap(), h.elements());
        }
        contract(&bytes)?;
    }

    #[test]
    fn mutated_valid_files_are_refused_or_read_whole(
        bytes in valid_file(),
        edits in prop::collection::vec(mutation(), 1..6),
    ) {
        contract(&mutate(bytes, &edits))?;
    }

    #[test]
    fn assembled_headers_are_refused_or_read_whole(bytes in assembled_file()) {
        contract(&bytes)?;
    }
}
