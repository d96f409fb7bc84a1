//! Writing screenshots of the views as PNG files.

use egui::{ColorImage, Rect};

/// Crop (in pixels) and write a screenshot as PNG.
pub fn write_png(path: &std::path::Path, image: &ColorImage, crop: Option<Rect>) -> anyhow::Result<()> {
    let (x0, y0, w, h) = crop_box(image.size, crop);
    let mut rgba = Vec::with_capacity(4 * w * h);
    for y in y0..y0 + h {
        for x in x0..x0 + w {
            rgba.extend_from_slice(&image.pixels[y * image.size[0] + x].to_srgba_unmultiplied());
        }
    }
    let image = winslow::io::picture::Image { width: w, height: h, rgba };
    winslow::io::write(path, &winslow::io::Output::Picture(&image))?;
    Ok(())
}

/// The pixel box `(x, y, width, height)` of `crop` within an image of `size`, clamped
/// (the whole image without a crop or when the crop misses it).
pub fn crop_box(size: [usize; 2], crop: Option<Rect>) -> (usize, usize, usize, usize) {
    let whole = (0, 0, size[0], size[1]);
    let Some(r) = crop else { return whole };
    let clamp = |v: f32, hi: usize| (v.round().max(0.0) as usize).min(hi);
    let (x0, x1) = (clamp(r.min.x, size[0]), clamp(r.max.x, size[0]));
    let (y0, y1) = (clamp(r.min.y, size[1]), clamp(r.max.y, size[1]));
    if x1 <= x0 || y1 <= y0 {
        return whole;
    }
    (x0, y0, x1 - x0, y1 - y0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::fold_colour;
    use egui::{Color32, Pos2};

    #[test]
    fn crop_boxes_are_clamped() {
        assert_eq!(crop_box([100, 50], None), (0, 0, 100, 50));
        let r = Rect::from_min_max(Pos2::new(10.2, 5.0), Pos2::new(60.0, 80.0));
        assert_eq!(crop_box([100, 50], Some(r)), (10, 5, 50, 45));
        let off = Rect::from_min_max(Pos2::new(200.0, 5.0), Pos2::new(300.0, 80.0));
        assert_eq!(crop_box([100, 50], Some(off)), (0, 0, 100, 50));
    }

    #[test]
    fn png_round_trip() {
        let mut img = ColorImage::filled([4, 3], Color32::from_rgb(10, 20, 30));
        img.pixels[4 + 2] = fold_colour();
        let scratch = tempfile::tempdir().unwrap();
        let path = scratch.path().join("crop.png");
        let crop = Rect::from_min_max(Pos2::new(1.0, 1.0), Pos2::new(3.0, 3.0));
        write_png(&path, &img, Some(crop)).unwrap();
        let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
        let mut reader = dec.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (2, 2));
        // pixel (2, 1) of the image is (1, 0) of the crop
        assert_eq!(&buf[4..8], &[255, 0, 255, 255]);
        assert_eq!(&buf[0..4], &[10, 20, 30, 255]);
    }
}
