//! The figure's font inside an SVG file, so the text looks the same in every
//! viewer whatever fonts its machine has: an `@font-face` whose source is
//! the TrueType file as a base64 `data:` URI, in a `<style>` element at the
//! top of the image (plotters' SVG backend only names a family).

use base64::Engine;

/// `svg` with a font face named `family` made of `ttf`, placed right after
/// the opening `<svg>` tag so it applies to every text element.
///
/// # Errors
/// When `svg` has no opening `<svg` tag (not plotters' output).
pub fn embed(svg: &str, family: &str, ttf: &[u8]) -> Result<String, String> {
    let open = svg
        .find("<svg")
        .and_then(|at| Some(at + svg[at..].find('>')? + 1))
        .ok_or("the SVG has no <svg> element")?;
    let data = base64::engine::general_purpose::STANDARD.encode(ttf);
    let style = format!(
        "\n<style type=\"text/css\">@font-face {{ font-family: \"{family}\"; \
         src: url(\"data:font/ttf;base64,{data}\") format(\"truetype\"); }}</style>"
    );
    let mut out = String::with_capacity(svg.len() + style.len());
    out.push_str(&svg[..open]);
    out.push_str(&style);
    out.push_str(&svg[open..]);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_face_goes_inside_the_svg_element() {
        let svg = "<svg width=\"2\" height=\"2\" xmlns=\"http://www.w3.org/2000/svg\">\n<text>a</text>\n</svg>\n";
        let out = embed(svg, "F", b"\x00\x01\xff").unwrap();
        let style = out.find("<style").unwrap();
        assert!(out.find('>').unwrap() < style && style < out.find("<text").unwrap());
        assert!(out.contains("font-family: \"F\"; src: url(\"data:font/ttf;base64,AAH/\")"));
        assert!(out.ends_with("<text>a</text>\n</svg>\n"));
        assert!(embed("<text>a</text>", "F", b"").is_err());
    }
}
