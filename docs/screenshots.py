"""Screenshots of the 3-D viewer for the documentation: the pages ``snakehead demo`` writes, in headless Chromium.

    snakehead demo --out demo-output
    python docs/screenshots.py demo-output          # writes docs/_static/viewer_spheres.png, viewer_hole.png

Needs Debian's ``chromium`` and ``chromium-driver`` (bash .ci/setup installs them) and Selenium.
"""
from __future__ import annotations

import argparse
import shutil
import time
from pathlib import Path

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By
from selenium.webdriver.support import expected_conditions as EC
from selenium.webdriver.support.ui import WebDriverWait

STATIC = Path(__file__).resolve().parent / "_static"


def browser(width: int, height: int) -> webdriver.Chrome:
    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium") or "chromium"
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--use-angle=swiftshader",
                "--enable-unsafe-swiftshader", f"--window-size={width},{height}", "--force-device-scale-factor=1"):
        options.add_argument(arg)
    return webdriver.Chrome(service=Service(shutil.which("chromedriver") or "chromedriver"), options=options)


def shoot(driver: webdriver.Chrome, page: Path, out: Path, at: float) -> None:
    """Open ``page``, pause at ``at`` (a share of the motion's duration) and save a screenshot to ``out``."""
    driver.get(page.resolve().as_uri())
    wait = WebDriverWait(driver, 120)
    slider = wait.until(EC.presence_of_element_located((By.CSS_SELECTOR, ".mantine-Slider-root")))
    for button in driver.find_elements(By.CSS_SELECTOR, ".mantine-Notification-closeButton"):
        button.click()  # "software WebGL" notice: true here, not for a reader's browser
    width = slider.size["width"]
    ActionChains(driver).move_to_element_with_offset(slider, int((at - 0.5) * width), 0).click().perform()
    time.sleep(8.0)  # SwiftShader draws slowly
    driver.save_screenshot(str(out))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("demo_output", type=Path, help="the --out folder of snakehead demo")
    parser.add_argument("--at", type=float, default=0.8, help="where on the time slider (0-1; default 0.8)")
    args = parser.parse_args()
    driver = browser(1100, 700)
    try:
        for name in ("spheres", "hole"):
            out = STATIC / f"viewer_{name}.png"
            shoot(driver, args.demo_output / f"{name}.html", out, args.at)
            print("wrote", out)
    finally:
        driver.quit()


if __name__ == "__main__":
    main()
