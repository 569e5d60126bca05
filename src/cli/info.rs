//! `texflow info`: the EGL devices with their renderer, GL version and limits.

use texflow::gl::{list_devices, Context};

pub fn info(json: bool) -> texflow::Result<()> {
    let devices = list_devices()?;
    let mut rows = Vec::new();
    let mut first = None;
    for d in &devices {
        let ctx = Context::new(d.index);
        let limits = ctx.as_ref().map(|c| c.limits().clone());
        if let (None, Ok(c)) = (&first, &ctx) {
            first = Some(texflow::bench::DeviceRecord::of(c));
        }
        // One vendor in text and JSON: EGL's, else GL_VENDOR, else "unknown".
        let vendor = d
            .vendor
            .clone()
            .or_else(|| limits.as_ref().ok().map(|l| l.vendor.clone()))
            .unwrap_or_else(|| "unknown".into());
        if !json {
            println!(
                "device {}: {} ({}){}",
                d.index,
                d.name.as_deref().unwrap_or(if d.software {
                    "Mesa software device"
                } else {
                    "unnamed"
                }),
                vendor,
                if d.software { ", software" } else { "" }
            );
            match &limits {
                Ok(l) => {
                    println!("  renderer              {}", l.renderer);
                    println!("  GL version            {}", l.version);
                    println!("  GLSL version          {}", l.glsl_version);
                    println!("  max texture size      {}", l.max_texture_size);
                    println!("  max 3D texture size   {}", l.max_3d_texture_size);
                    println!("  max draw buffers      {}", l.max_draw_buffers);
                    println!("  max colour attachments {}", l.max_color_attachments);
                    println!(
                        "  vertex texture units  {}",
                        l.max_vertex_texture_image_units
                    );
                    println!(
                        "  max viewport          {}x{}",
                        l.max_viewport[0], l.max_viewport[1]
                    );
                    println!("  RGBA32F colour buffer {}", yes(l.float32_color_buffer));
                    println!("  RGBA16F colour buffer {}", yes(l.float16_color_buffer));
                    println!("  KHR_debug             {}", yes(l.khr_debug));
                    println!(
                        "  point size range      {} to {} pixels",
                        l.point_size_range[0], l.point_size_range[1]
                    );
                }
                Err(e) => println!("  no usable context: {e}"),
            }
        }
        rows.push(serde_json::json!({
            "index": d.index,
            "name": d.name,
            "vendor": vendor,
            "software": d.software,
            "drm_node": d.drm_node,
            "limits": limits.as_ref().ok(),
            "error": limits.as_ref().err().map(|e| e.to_string()),
        }));
    }
    if json {
        let v = serde_json::json!({
            "texflow_version": env!("CARGO_PKG_VERSION"),
            "schema": "texflow.info/1",
            "device": first,
            "devices": rows,
        });
        println!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
    }
    Ok(())
}

pub fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}
