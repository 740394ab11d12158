//! The page's files, embedded so that the view works offline: the page, its script and three.js
//! (vendored from the npm registry with its licence, `assets/view/vendor/`).

/// A file of the page: its path under the view's address, content type and bytes.
pub struct Asset {
    pub path: &'static str,
    pub content_type: &'static str,
    pub body: &'static [u8],
}

const JS: &str = "text/javascript; charset=utf-8";

/// Every file the page loads; the page itself at "".
pub const ASSETS: &[Asset] = &[
    Asset {
        path: "",
        content_type: "text/html; charset=utf-8",
        body: include_bytes!("../../assets/view/index.html"),
    },
    Asset {
        path: "view.js",
        content_type: JS,
        body: include_bytes!("../../assets/view/view.js"),
    },
    Asset {
        path: "vendor/three.module.js",
        content_type: JS,
        body: include_bytes!("../../assets/view/vendor/three.module.js"),
    },
    Asset {
        path: "vendor/three.core.js",
        content_type: JS,
        body: include_bytes!("../../assets/view/vendor/three.core.js"),
    },
    Asset {
        path: "vendor/OrbitControls.js",
        content_type: JS,
        body: include_bytes!("../../assets/view/vendor/OrbitControls.js"),
    },
    Asset {
        path: "vendor/LICENSE",
        content_type: "text/plain; charset=utf-8",
        body: include_bytes!("../../assets/view/vendor/LICENSE"),
    },
];

/// The file at `path` (relative to the view's address), if there is one.
pub fn find(path: &str) -> Option<&'static Asset> {
    ASSETS.iter().find(|a| a.path == path)
}
