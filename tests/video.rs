//! `render --video`: the animation decodes back to one frame per written frame, of the frame
//! size, and its first frame is the PNG frame of the same run (exactly for APNG; for GIF exactly
//! when the frame has at most 256 colours, which the gif encoder then keeps as its palette).
//! A missing ffmpeg is refused before the run, with exit code 2.

mod common;

use common::cli::{stderr, texflow};

use std::path::Path;
use std::process::Command;

/// Renders a small fountain (5 frames, every 2nd written: frames 0, 2, 4) into `video` and PNGs.
fn render(video: &Path, frames: &Path) {
    let o = texflow(&[
        "render",
        "fountain",
        "--frames",
        "5",
        "--every",
        "2",
        "--particles",
        "16",
        "--resolution",
        "64x48",
        "--video",
        video.to_str().unwrap(),
        "--out",
        frames.to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success(), "render failed: {}", stderr(&o));
}

fn png_frame(dir: &Path, index: u64) -> image::RgbImage {
    image::open(dir.join(format!("frame_{index:05}.png")))
        .expect("PNG frame")
        .to_rgb8()
}

fn colours(img: &image::RgbImage) -> usize {
    img.pixels()
        .map(|p| p.0)
        .collect::<std::collections::HashSet<_>>()
        .len()
}

#[test]
fn apng_holds_every_written_frame_losslessly() {
    let dir = tempfile::tempdir().unwrap();
    let (video, frames) = (dir.path().join("run.png"), dir.path().join("frames"));
    render(&video, &frames);
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(&video).unwrap(),
    ));
    let mut reader = decoder.read_info().unwrap();
    let info = reader.info();
    assert_eq!((info.width, info.height), (64, 48));
    let control = info.animation_control().expect("an APNG has an acTL chunk");
    assert_eq!(control.num_frames, 3, "frames 0, 2 and 4");
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    for index in [0u64, 2, 4] {
        let out = reader.next_frame(&mut buf).unwrap();
        assert_eq!((out.width, out.height), (64, 48));
        let frame = &buf[..out.buffer_size()];
        assert_eq!(
            frame,
            png_frame(&frames, index).as_raw().as_slice(),
            "APNG frame of frame {index} differs from its PNG"
        );
    }
    assert!(
        texflow::output::unfinished().is_empty(),
        "no temporary file left"
    );
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

#[test]
fn gif_frames_match_the_png_frames_after_the_palette() {
    use image::AnimationDecoder;
    let dir = tempfile::tempdir().unwrap();
    let (video, frames) = (dir.path().join("run.gif"), dir.path().join("frames"));
    render(&video, &frames);
    let decoder = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(
        std::fs::File::open(&video).unwrap(),
    ))
    .unwrap();
    let decoded = decoder.into_frames().collect_frames().unwrap();
    assert_eq!(decoded.len(), 3, "frames 0, 2 and 4");
    for (frame, index) in decoded.iter().zip([0u64, 2, 4]) {
        let gif = image::DynamicImage::ImageRgba8(frame.buffer().clone()).to_rgb8();
        assert_eq!(gif.dimensions(), (64, 48));
        let png = png_frame(&frames, index);
        let n = colours(&png);
        eprintln!("frame {index}: {n} colours");
        if n <= 256 {
            // The gif encoder keeps a frame of at most 256 colours as its exact palette.
            assert_eq!(gif, png, "GIF frame {index} differs from its PNG");
        } else {
            // NeuQuant: each channel within 1/8 of full scale, and on average within 2 levels.
            let diffs: Vec<u32> = gif
                .as_raw()
                .iter()
                .zip(png.as_raw())
                .map(|(a, b)| a.abs_diff(*b) as u32)
                .collect();
            let max = *diffs.iter().max().unwrap();
            let mean = diffs.iter().sum::<u32>() as f64 / diffs.len() as f64;
            assert!(
                max <= 32 && mean <= 2.0,
                "frame {index}: max {max}, mean {mean}"
            );
        }
    }
    assert!(
        frames.join("frame_00000.png").exists() && !frames.join("frame_00001.png").exists(),
        "--every 2 writes frames 0, 2, 4"
    );
}

#[test]
fn mp4_without_ffmpeg_is_refused_before_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let video = dir.path().join("run.mp4");
    let frames = dir.path().join("frames");
    let o = Command::new(env!("CARGO_BIN_EXE_texflow"))
        .args(["render", "fountain", "--frames", "2", "--video"])
        .arg(&video)
        .arg("--out")
        .arg(&frames)
        // A PATH with no ffmpeg on it.
        .env("PATH", dir.path())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("ffmpeg") && e.contains(".gif"), "{e}");
    assert!(!video.exists() && !frames.exists(), "nothing written");
}

#[test]
fn unknown_video_extension_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let video = dir.path().join("run.avi");
    let o = texflow(&[
        "render",
        "fountain",
        "--frames",
        "2",
        "--video",
        video.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(e.contains(".gif") && e.contains(".webm"), "{e}");
    assert!(!video.exists());
}

#[test]
fn video_alone_writes_no_frame_folder() {
    let dir = tempfile::tempdir().unwrap();
    let video = dir.path().join("run.gif");
    let o = Command::new(env!("CARGO_BIN_EXE_texflow"))
        .args([
            "render",
            "fountain",
            "--frames",
            "2",
            "--particles",
            "16",
            "--resolution",
            "32",
            "-q",
            "--video",
        ])
        .arg(&video)
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(video.exists());
    assert!(
        !dir.path().join("frames").exists(),
        "--video alone writes only the video"
    );
}

#[test]
fn mp4_and_webm_through_ffmpeg_have_every_frame_padded_to_even_sides() {
    if texflow::output::video::find_ffmpeg().is_none()
        || Command::new("ffprobe").arg("-version").output().is_err()
    {
        eprintln!("skipped: no ffmpeg/ffprobe on PATH (apt-get install ffmpeg)");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for ext in ["mp4", "webm"] {
        let video = dir.path().join(format!("run.{ext}"));
        let o = texflow(&[
            "render",
            "fountain",
            "--frames",
            "6",
            "--every",
            "2",
            "--particles",
            "16",
            "--resolution",
            "33x17",
            "-q",
            "--video",
            video.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let probe = Command::new("ffprobe")
            .args(["-v", "error", "-select_streams", "v", "-count_frames"])
            .args([
                "-show_entries",
                "stream=width,height,nb_read_frames",
                "-of",
                "csv=p=0",
            ])
            .arg(&video)
            .output()
            .unwrap();
        let line = String::from_utf8_lossy(&probe.stdout).trim().to_owned();
        assert_eq!(line, "34,18,3", "{ext}: width, height, frames");
    }
}
