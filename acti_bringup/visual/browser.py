"""Debian's headless Chromium driven by selenium through Debian's chromedriver: the browser of the
view's test and benchmark. Nothing is ever downloaded: both binaries come from apt
(`make test` installs them), and a missing one is an error that says so, never a skip."""
from __future__ import annotations

import os

import numpy as np

CHROMIUM = os.environ.get("ACTI_CHROMIUM", "/usr/lib/chromium/chromium-headless-shell")
CHROMEDRIVER = os.environ.get("ACTI_CHROMEDRIVER", "/usr/bin/chromedriver")
APT_PACKAGES = "chromium-headless-shell chromium-driver"
# software WebGL: the page renders on a machine without a GPU
FLAGS = ("--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
         "--disable-dev-shm-usage", "--hide-scrollbars")


def missing() -> str | None:
    """Why the browser cannot start, or None."""
    for path in (CHROMIUM, CHROMEDRIVER):
        if not os.access(path, os.X_OK):
            return f"{path} is missing: apt-get install {APT_PACKAGES} (make test does)"
    return None


def open_browser(width: int = 1100, height: int = 750):
    """A selenium WebDriver on headless Chromium; `quit()` ends it."""
    why = missing()
    if why:
        raise RuntimeError(why)
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in FLAGS + (f"--window-size={width},{height}",):
        options.add_argument(flag)
    return webdriver.Chrome(options=options, service=Service(CHROMEDRIVER))


def screenshot(driver, attempts: int = 6) -> np.ndarray:
    """The page as an RGB array (height × width × 3, uint8). Software WebGL on a loaded machine
    can keep the renderer busy past chromedriver's 10 s: such a timeout is tried again."""
    import io

    import matplotlib.image as mpimg
    from selenium.common.exceptions import TimeoutException
    for attempt in range(attempts):
        try:
            png = driver.get_screenshot_as_png()
            break
        except TimeoutException:
            if attempt == attempts - 1:
                raise
    rgb = mpimg.imread(io.BytesIO(png), format="png")[:, :, :3]
    return (rgb * 255).astype(np.uint8)



def robot_pixels(image: np.ndarray, panel_width: int = 360, top: int = 160) -> np.ndarray:
    """Mask of the robot's orange links in a screenshot of the view (the GUI panel on the right
    and the notices at the top cut off)."""
    view = image[top:, :image.shape[1] - panel_width].astype(int)
    r, g, b = view[..., 0], view[..., 1], view[..., 2]
    return (r > 140) & (g > 0.3 * r) & (g < 0.75 * r) & (b < 0.45 * r)


def dismiss_notices(driver) -> bool:
    """Close the page's notices (viser tells when WebGL runs in software); whether any was."""
    return bool(driver.execute_script(
        "let n = 0; for (const b of document.querySelectorAll('[class*=Notification] button'))"
        " { b.click(); n++; } return n;"))
