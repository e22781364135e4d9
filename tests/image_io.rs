//! PFM, EXR and PNG output: round trips, orientation, endianness, tone mapping, errors.

use std::path::PathBuf;

use penumbra::raster::io::{read_pfm, srgb_oetf, to_srgb8, write_exr, write_pfm, write_png};

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("penumbra-image-io-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A 5x3 image, different everywhere, with values that f32 text would not round-trip.
fn test_image() -> (u32, u32, Vec<[f32; 3]>) {
    let (w, h) = (5u32, 3u32);
    let px = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            [
                x as f32 + 0.1 * y as f32,
                -(y as f32) * std::f32::consts::PI,
                1e-30 * (i as f32 + 1.0) + f32::EPSILON,
            ]
        })
        .collect();
    (w, h, px)
}

#[test]
fn pfm_round_trip_is_bit_exact_and_keeps_orientation() {
    let (w, h, px) = test_image();
    let path = temp("round_trip.pfm");
    write_pfm(&path, w, h, &px).unwrap();
    let (w2, h2, px2) = read_pfm(&path).unwrap();
    assert_eq!((w2, h2), (w, h));
    for (a, b) in px.iter().zip(&px2) {
        for c in 0..3 {
            assert_eq!(a[c].to_bits(), b[c].to_bits());
        }
    }
    // On disk: header, then the bottom row first, little endian.
    let bytes = std::fs::read(&path).unwrap();
    let header = b"PF\n5 3\n-1.0\n";
    assert_eq!(&bytes[..header.len()], header);
    assert_eq!(bytes.len(), header.len() + 5 * 3 * 12);
    let first = f32::from_le_bytes(bytes[header.len()..header.len() + 4].try_into().unwrap());
    let bottom_left = px[((h - 1) * w) as usize][0];
    assert_eq!(first, bottom_left);
    assert_eq!(bottom_left, 0.2); // x = 0, y = 2 (the bottom row)
}

#[test]
fn pfm_reads_hand_made_big_endian_and_greyscale() {
    // 2x2, big endian (positive scale), rows bottom to top: bottom = (1,2,3) (4,5,6),
    // top = (7,8,9) (10,11,12). Header with extra spaces and a scale other than 1.
    let mut bytes = b"PF\n2  2\n2.5\n".to_vec();
    for v in 1..=12 {
        bytes.extend_from_slice(&(v as f32).to_be_bytes());
    }
    let path = temp("big_endian.pfm");
    std::fs::write(&path, &bytes).unwrap();
    let (w, h, px) = read_pfm(&path).unwrap();
    assert_eq!((w, h), (2, 2));
    assert_eq!(
        px,
        vec![
            [7.0, 8.0, 9.0],
            [10.0, 11.0, 12.0],
            [1.0, 2.0, 3.0],
            [4.0, 5.0, 6.0]
        ]
    );

    let mut bytes = b"Pf 3 1 -1.0\n".to_vec();
    for v in [0.5f32, 1.5, -2.0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let path = temp("grey.pfm");
    std::fs::write(&path, &bytes).unwrap();
    let (w, h, px) = read_pfm(&path).unwrap();
    assert_eq!((w, h), (3, 1));
    assert_eq!(px, vec![[0.5; 3], [1.5; 3], [-2.0; 3]]);
}

#[test]
fn pfm_errors_name_the_file() {
    let missing = temp("does-not-exist.pfm");
    let e = read_pfm(&missing).unwrap_err();
    assert!(e.to_string().contains("does-not-exist.pfm"), "{e}");

    for (name, bytes) in [
        ("magic.pfm", b"P6\n1 1\n255\n\0\0\0".to_vec()),
        ("short.pfm", b"PF\n2 2\n-1.0\n\0\0\0\0".to_vec()),
        (
            "scale.pfm",
            b"PF\n1 1\n0.0\n\0\0\0\0\0\0\0\0\0\0\0\0".to_vec(),
        ),
        ("truncated.pfm", b"PF\n1".to_vec()),
    ] {
        let path = temp(name);
        std::fs::write(&path, bytes).unwrap();
        let e = read_pfm(&path).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidData, "{name}: {e}");
        assert!(e.to_string().contains(name), "{e}");
    }

    let e = write_pfm(&temp("size.pfm"), 2, 2, &[[0.0; 3]; 3]).unwrap_err();
    assert!(e.to_string().contains("size.pfm"), "{e}");
    let e = write_exr(&temp("size.exr"), 2, 2, &[[0.0; 3]; 3]).unwrap_err();
    assert!(format!("{e:#}").contains("size.exr"), "{e:#}");
    let e = write_png(&temp("size.png"), 2, 2, &[[0.0; 3]; 3], 0.0).unwrap_err();
    assert!(format!("{e:#}").contains("size.png"), "{e:#}");
    let dir = temp("no-such-dir").join("x.png");
    let e = write_png(&dir, 1, 1, &[[0.0; 3]], 0.0).unwrap_err();
    assert!(format!("{e:#}").contains("x.png"), "{e:#}");
}

#[test]
fn exr_round_trip_through_the_exr_crate() {
    use exr::prelude::*;
    let (w, h, px) = test_image();
    let path = temp("image.exr");
    write_exr(&path, w, h, &px).unwrap();
    let image = read_first_rgba_layer_from_file(
        &path,
        |res: Vec2<usize>, _| (res, vec![[0f32; 3]; res.width() * res.height()]),
        |(res, pixels): &mut (Vec2<usize>, Vec<[f32; 3]>),
         pos: Vec2<usize>,
         (r, g, b, _a): (f32, f32, f32, f32)| {
            pixels[pos.y() * res.width() + pos.x()] = [r, g, b];
        },
    )
    .unwrap();
    let (res, pixels) = &image.layer_data.channel_data.pixels;
    assert_eq!((res.width(), res.height()), (w as usize, h as usize));
    // Stored as f32: bit exact, row 0 at the top (OpenEXR's y grows downwards).
    for (a, b) in px.iter().zip(pixels) {
        for c in 0..3 {
            assert_eq!(a[c].to_bits(), b[c].to_bits());
        }
    }
    let channels = &image.layer_data.channel_data.channels;
    assert_eq!(channels.0.sample_type, SampleType::F32);
}

#[test]
fn png_tone_mapping() {
    assert_eq!(to_srgb8(0.0, 0.0), 0);
    assert_eq!(to_srgb8(1.0, 0.0), 255);
    assert_eq!(to_srgb8(0.5, 0.0), 188);
    assert_eq!(to_srgb8(0.25, 1.0), 188); // exposure +1 doubles
    assert_eq!(to_srgb8(4.0, -3.0), 188); // and -3 divides by 8
    assert_eq!(to_srgb8(7.0, 0.0), 255);
    assert_eq!(to_srgb8(-1.0, 0.0), 0);
    assert_eq!(to_srgb8(f32::NAN, 0.0), 0);
    assert_eq!(to_srgb8(f32::INFINITY, 0.0), 255);
    // Linear segment and continuity of the exact piecewise curve.
    assert!((srgb_oetf(0.001) - 0.01292).abs() < 1e-17);
    assert!((srgb_oetf(0.003_130_8) - srgb_oetf(0.003_130_800_1)).abs() < 1e-7);
    assert_eq!(to_srgb8(0.0031308, 0.0), 10); // 0.04045 * 255 = 10.3

    let path = temp("tone.png");
    let px = [[0.0, 0.5, 1.0], [0.25, 2.0, -1.0]];
    write_png(&path, 1, 2, &px, 0.0).unwrap();
    let img = image::open(&path).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (1, 2));
    assert_eq!(img.get_pixel(0, 0).0, [0, 188, 255]); // row 0 at the top
    assert_eq!(img.get_pixel(0, 1).0, [137, 255, 0]);
}
